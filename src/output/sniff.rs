//! Recognising a file by its first bytes, so that a command replaces or removes only files it
//! wrote itself, never a user's file that merely has the same name.

use std::io::Read;
use std::path::Path;

/// The first bytes of every PNG file.
pub const PNG_SIGNATURE: [u8; 8] = [0x89, b'P', b'N', b'G', b'\r', b'\n', 0x1a, b'\n'];

/// Whether the file at `path` starts with `prefix` (false if it cannot be read).
pub fn starts_with(path: &Path, prefix: &[u8]) -> bool {
    let mut head = vec![0; prefix.len()];
    std::fs::File::open(path)
        .and_then(|mut f| f.read_exact(&mut head))
        .is_ok_and(|()| head == prefix)
}

/// Width and height from a PNG file's header, if it is one.
pub fn png_size(path: &Path) -> Option<(u32, u32)> {
    let mut head = [0u8; 24];
    std::fs::File::open(path).ok()?.read_exact(&mut head).ok()?;
    if head[..8] != PNG_SIGNATURE || &head[12..16] != b"IHDR" {
        return None;
    }
    let word = |i: usize| u32::from_be_bytes([head[i], head[i + 1], head[i + 2], head[i + 3]]);
    Some((word(16), word(20)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_png_header_gives_its_size_and_anything_else_gives_none() {
        let dir = tempfile::tempdir().unwrap();
        let png = dir.path().join("a.png");
        let mut bytes = PNG_SIGNATURE.to_vec();
        bytes.extend([0, 0, 0, 13]);
        bytes.extend(b"IHDR");
        bytes.extend(1000u32.to_be_bytes());
        bytes.extend(650u32.to_be_bytes());
        std::fs::write(&png, &bytes).unwrap();
        assert_eq!(png_size(&png), Some((1000, 650)));
        assert!(starts_with(&png, &PNG_SIGNATURE));

        let text = dir.path().join("b.png");
        std::fs::write(&text, "not a png, but long enough to have 24 bytes").unwrap();
        assert_eq!(png_size(&text), None);
        assert!(!starts_with(&text, &PNG_SIGNATURE));
        assert!(!starts_with(&dir.path().join("missing"), b"x"));
    }
}
