//! Recognising a file's format by its first bytes — a trace's `timeline.png` is checked to be
//! a PNG before a report embeds it. Never whose a file is: that is the directory's record
//! ([`super::record`]).

use std::io::Read;
use std::path::Path;

use crate::io::capped::{self, Kind};

/// The first bytes of every PNG file.
pub const PNG_SIGNATURE: [u8; 8] = [0x89, b'P', b'N', b'G', b'\r', b'\n', 0x1a, b'\n'];

/// Whether the file at `path` (read as a `kind`, see [`capped`]) starts with the PNG
/// signature; refusals and read errors are errors, a short file is not a PNG.
pub fn is_png(path: &Path, kind: Kind) -> anyhow::Result<bool> {
    let mut head = Vec::with_capacity(PNG_SIGNATURE.len());
    capped::open(path, kind)?
        .take(PNG_SIGNATURE.len() as u64)
        .read_to_end(&mut head)
        .map_err(|e| capped::io_error(e, path))?;
    Ok(head == PNG_SIGNATURE)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_png_is_told_from_text_by_its_signature() {
        let dir = tempfile::tempdir().unwrap();
        let png = dir.path().join("a.png");
        let mut bytes = PNG_SIGNATURE.to_vec();
        bytes.extend(b"rest");
        std::fs::write(&png, &bytes).unwrap();
        assert!(is_png(&png, capped::TIMELINE_PNG).unwrap());
        let text = dir.path().join("b.png");
        std::fs::write(&text, "not a png").unwrap();
        assert!(!is_png(&text, capped::TIMELINE_PNG).unwrap());
        std::fs::write(&text, "").unwrap();
        assert!(!is_png(&text, capped::TIMELINE_PNG).unwrap());
    }
}
