//! The tree of bodies: parents by name, cycles, roots, and the body order
//! (pre-order from the root).

use std::collections::HashMap;

use super::{Parent, RawBody};
use crate::diagnostic::{closest, Problem};
use crate::input::load::{Loader, TreeReader};
use crate::yaml::Span;

impl Loader {
    /// Parents, cycles and roots; returns each body's parent (file indices)
    /// and the body order (pre-order if the tree is valid, file order
    /// otherwise).
    pub(super) fn tree(
        &mut self,
        raws: &[RawBody<'_>],
        bodies_key: Span,
    ) -> (Vec<Option<usize>>, Vec<usize>) {
        let n = raws.len();
        let by_name: HashMap<&str, usize> = raws
            .iter()
            .enumerate()
            .map(|(i, r)| (r.name.as_str(), i))
            .collect();
        let mut parents = vec![None; n];
        let mut detached = vec![false; n];
        let mut roots = Vec::new();
        for (i, raw) in raws.iter().enumerate() {
            match &raw.parent {
                Parent::Root => roots.push(i),
                Parent::Bad => detached[i] = true,
                Parent::Named(u) => match by_name.get(u.name.as_str()) {
                    Some(&p) => parents[i] = Some(p),
                    None => {
                        detached[i] = true;
                        let suggestion = closest(&u.name, raws.iter().map(|r| r.name.as_str()))
                            .map(str::to_string);
                        self.report(
                            u.span,
                            u.path.clone(),
                            Problem::UnknownBody {
                                role: "parent",
                                name: u.name.clone(),
                                suggestion,
                            },
                        );
                    }
                },
            }
        }

        // Cycles: follow parent links; 1 = on the current walk, 2 = reaches a
        // root or a detached body, 3 = in or below a cycle.
        let mut state = vec![0u8; n];
        let mut cycles = 0;
        for start in 0..n {
            let mut walk = Vec::new();
            let mut j = Some(start);
            while let Some(k) = j {
                if state.get(k).copied() != Some(0) {
                    break;
                }
                state[k] = 1;
                walk.push(k);
                j = parents.get(k).copied().flatten();
            }
            let fate = match j {
                None => 2,
                Some(k) if state.get(k).copied() == Some(1) => {
                    let pos = walk.iter().position(|&w| w == k).unwrap_or(0);
                    let cycle = walk.get(pos..).unwrap_or(&[]);
                    // Start the message at the cycle's first body in the file.
                    let first = cycle.iter().copied().min().unwrap_or(k);
                    let mut names = Vec::new();
                    let mut c = first;
                    for _ in 0..=cycle.len() {
                        names.push(raws.get(c).map(|r| r.name.clone()).unwrap_or_default());
                        c = parents.get(c).copied().flatten().unwrap_or(first);
                    }
                    if let Some(r) = raws.get(first) {
                        self.report(r.span, r.path.clone(), Problem::Cycle { bodies: names });
                    }
                    cycles += 1;
                    3
                }
                Some(k) => state.get(k).copied().unwrap_or(3),
            };
            for k in walk {
                state[k] = fate;
            }
        }

        if let Some((&first, others)) = roots.split_first() {
            for &other in others {
                if let (Some(f), Some(o)) = (raws.get(first), raws.get(other)) {
                    self.report(
                        o.span,
                        o.path.clone(),
                        Problem::SecondRoot {
                            first: f.name.clone(),
                            second: o.name.clone(),
                        },
                    );
                }
            }
        } else if cycles == 0 && !detached.contains(&true) {
            self.report(bodies_key, "bodies", Problem::NoRoot);
        }

        let valid = roots.len() == 1 && cycles == 0 && !detached.contains(&true);
        let order = match roots.first() {
            Some(&root) if valid => {
                let mut children = vec![Vec::new(); n];
                for (i, p) in parents.iter().enumerate() {
                    if let Some(c) = p.and_then(|p| children.get_mut(p)) {
                        c.push(i);
                    }
                }
                let mut order = Vec::with_capacity(n);
                let mut stack = vec![root];
                while let Some(b) = stack.pop() {
                    order.push(b);
                    if let Some(c) = children.get(b) {
                        stack.extend(c.iter().rev());
                    }
                }
                order
            }
            _ => (0..n).collect(),
        };
        (parents, order)
    }
}
