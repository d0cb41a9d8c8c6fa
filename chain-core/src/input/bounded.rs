//! The one bounded reader every input of the toolkit goes through: machine
//! files, settings, values files and their CSV tables, measurement and
//! candidate CSVs, posteriors, and the command line's CSV inputs (`chain
//! inverse --pose`, `chain path --axes`, `chain compensate FILE`, stdin).
//!
//! A reader asks for at most `limit + 1` bytes through [`Read::take`] and its
//! buffer grows by doubling but never past `limit + 1` bytes, so a FIFO or a
//! device (`/dev/zero`) costs at most that much memory before it is refused
//! with its name and the limit. The bounds of each kind of input are the
//! constants below (`docs/robustness.md` says why each is what it is).

use std::fmt;
use std::io::Read;
use std::path::Path;

/// One MiB.
const MIB: usize = 1024 * 1024;

/// Machine files (`chain_core::load::load_file`): 16 MiB, a thousand times
/// the largest example.
pub const MACHINE_BYTES: usize = 16 * MIB;
/// Settings files of `chain motion`: 1 MiB (a few dozen keys).
pub const SETTINGS_BYTES: usize = MIB;
/// Values files and posteriors: 16 MiB, like the machine files they belong to.
pub const VALUES_BYTES: usize = 16 * MIB;
/// The CSV tables a values file names: 64 MiB (a million table points).
pub const TABLE_BYTES: usize = 64 * MIB;
/// Measurement and candidate CSVs (`chain identify`, `chain plan`): 256 MiB,
/// a few million measured points of a laser tracker or a ball bar.
pub const MEASUREMENT_BYTES: usize = 256 * MIB;
/// Pose and axes CSVs (`chain inverse --pose`, `chain path --axes`): 256 MiB,
/// a CAM program of several million blocks (a 10⁶-row axes file is ~60 MB).
pub const PATH_BYTES: usize = 256 * MIB;
/// The swing-angle measurements of `chain compensate FILE`: 16 MiB (a
/// measurement campaign is hundreds of rows).
pub const COMPENSATE_BYTES: usize = 16 * MIB;

/// Why a bounded read failed.
#[derive(Debug)]
pub enum ReadError {
    /// The file could not be opened or read.
    Io(std::io::Error),
    /// The input has more than `limit` bytes.
    TooLarge {
        /// The bound in bytes.
        limit: usize,
    },
}

impl fmt::Display for ReadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ReadError::Io(e) => write!(f, "{e}"),
            ReadError::TooLarge { limit } => {
                write!(f, "the file is too large (more than {})", describe(*limit))
            }
        }
    }
}

impl std::error::Error for ReadError {}

/// A byte count for messages: `16 MiB (16777216 bytes)`.
pub fn describe(limit: usize) -> String {
    if limit >= MIB && limit % MIB == 0 {
        format!("{} MiB = {limit} bytes", limit / MIB)
    } else {
        format!("{limit} bytes")
    }
}

/// The bytes of the file at `path`, at most `limit` of them.
pub fn read_path(path: &Path, limit: usize) -> Result<Vec<u8>, ReadError> {
    let file = std::fs::File::open(path).map_err(ReadError::Io)?;
    read_from(file, limit)
}

/// The bytes of `source` (a file, a pipe, stdin), at most `limit` of them:
/// at most `limit + 1` bytes are read and buffered.
pub fn read_from(source: impl Read, limit: usize) -> Result<Vec<u8>, ReadError> {
    let cap = limit.saturating_add(1);
    let mut source = source.take(cap as u64);
    let mut bytes: Vec<u8> = Vec::new();
    let mut chunk = [0u8; 64 * 1024];
    loop {
        let n = match source.read(&mut chunk) {
            Ok(0) => break,
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(ReadError::Io(e)),
        };
        if bytes.capacity() - bytes.len() < n {
            let want = (bytes.capacity() * 2).max(bytes.len() + n).min(cap);
            bytes.reserve_exact(want - bytes.len());
        }
        bytes.extend_from_slice(&chunk[..n]);
    }
    if bytes.len() > limit {
        return Err(ReadError::TooLarge { limit });
    }
    Ok(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_device_is_refused_at_the_bound_with_bounded_memory() {
        let zeros = std::io::repeat(0).take(10_000);
        match read_from(zeros, 4096) {
            Err(ReadError::TooLarge { limit }) => assert_eq!(limit, 4096),
            other => panic!("expected TooLarge, got {other:?}"),
        }
        let endless = std::io::repeat(7);
        assert!(matches!(
            read_from(endless, 3 * MIB),
            Err(ReadError::TooLarge { .. })
        ));
    }

    #[test]
    fn a_file_at_the_bound_is_read_whole() {
        let data: Vec<u8> = (0..5000u32).map(|i| (i % 251) as u8).collect();
        assert_eq!(read_from(&data[..], 5000).unwrap(), data);
        assert!(matches!(
            read_from(&data[..], 4999),
            Err(ReadError::TooLarge { limit: 4999 })
        ));
        assert_eq!(describe(16 * MIB), "16 MiB = 16777216 bytes".to_string());
    }
}
