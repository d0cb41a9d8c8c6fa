//! How a message quotes what it was given: shortened when long, and the
//! closest valid name when one is close.

/// The most characters of an input's text a message quotes
/// ([`shortened`]).
pub const QUOTED_CHARS: usize = 40;

/// `text` as a message quotes it: whole when it has at most
/// [`QUOTED_CHARS`] characters, else its first [`QUOTED_CHARS`] and `…`
/// (so a refused 5,000-digit cell is not echoed in full). The one
/// shortening of every located message (YAML scalars, CSV cells, names in
/// numbers).
pub fn shortened(text: &str) -> std::borrow::Cow<'_, str> {
    match text.char_indices().nth(QUOTED_CHARS) {
        None => std::borrow::Cow::Borrowed(text),
        Some((end, _)) => std::borrow::Cow::Owned(format!("{}…", &text[..end])),
    }
}

/// The closest candidate to `name` by edit distance, if it is close enough to
/// be a plausible typo (at most a third of the longer name's length, and at
/// least one edit is always allowed; a case-only difference always matches).
/// Failing that, a candidate of at least three characters that is a prefix of
/// `name` (`minimum` → `min`) or that `name` is a prefix of.
pub fn closest<'a, I>(name: &str, candidates: I) -> Option<&'a str>
where
    I: IntoIterator<Item = &'a str>,
{
    let lower = name.to_lowercase();
    let mut best: Option<(usize, &'a str)> = None;
    let mut prefixed: Option<&'a str> = None;
    for cand in candidates {
        if cand == name {
            continue;
        }
        let cl = cand.to_lowercase();
        let d = if cl == lower {
            0
        } else {
            edit_distance(&lower, &cl)
        };
        let longest = name.chars().count().max(cand.chars().count());
        let allowed = (longest / 3).max(1);
        if d <= allowed && best.is_none_or(|(bd, _)| d < bd) {
            best = Some((d, cand));
        }
        let shortest = name.chars().count().min(cand.chars().count());
        if prefixed.is_none() && shortest >= 3 && (lower.starts_with(&cl) || cl.starts_with(&lower))
        {
            prefixed = Some(cand);
        }
    }
    best.map(|(_, c)| c).or(prefixed)
}

/// Optimal-string-alignment distance (Levenshtein plus adjacent transpositions).
fn edit_distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().collect();
    let b: Vec<char> = b.chars().collect();
    let n = b.len();
    let mut prev2 = vec![0usize; n + 1];
    let mut prev: Vec<usize> = (0..=n).collect();
    let mut cur = vec![0usize; n + 1];
    for (i, &ca) in a.iter().enumerate() {
        cur[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let cost = usize::from(ca != cb);
            let mut v = (prev[j] + cost).min(prev[j + 1] + 1).min(cur[j] + 1);
            if i > 0 && j > 0 && a.get(i - 1) == Some(&cb) && b.get(j - 1) == Some(&ca) {
                v = v.min(prev2[j - 1] + 1);
            }
            cur[j + 1] = v;
        }
        std::mem::swap(&mut prev2, &mut prev);
        std::mem::swap(&mut prev, &mut cur);
    }
    prev[n]
}
