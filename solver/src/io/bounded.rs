//! A reader that refuses input no CSV file of ours would hold: a line longer than
//! [`MAX_LINE_BYTES`], or more lines than a bound. `--init /dev/zero` (endless bytes, no
//! newline) then fails after 4 KiB instead of filling memory, and an endless stream of short
//! lines fails after the bound instead of never returning. It also keeps the first line, so
//! the caller can read a comment the CSV parser skips.

use std::io::{self, Read};

/// The longest line accepted, bytes. A dump row is 9 numbers of at most 24 characters and an
/// index: under 250 bytes; 4 KiB leaves room for hand-written files with extra columns.
pub const MAX_LINE_BYTES: usize = 4096;

/// Why reading stopped early (carried inside an [`io::Error`] of kind `InvalidData`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum Overrun {
    /// A line is longer than [`MAX_LINE_BYTES`].
    #[error("line {line} is longer than {MAX_LINE_BYTES} bytes (is this a CSV file?)")]
    LongLine {
        /// 1-based line number.
        line: u64,
    },
    /// There are more lines than the bound.
    #[error("more than {max} lines")]
    TooManyLines {
        /// The bound.
        max: u64,
    },
}

/// Wraps a reader; see the module docs.
#[derive(Debug)]
pub struct BoundedLines<R> {
    inner: R,
    max_lines: u64,
    /// 1-based number of the line being read.
    line: u64,
    /// Bytes of that line so far.
    in_line: usize,
    first_line: Vec<u8>,
}

impl<R: Read> BoundedLines<R> {
    /// Reads `inner`, allowing at most `max_lines` lines.
    pub fn new(inner: R, max_lines: u64) -> Self {
        BoundedLines {
            inner,
            max_lines,
            line: 1,
            in_line: 0,
            first_line: Vec::new(),
        }
    }

    /// The first line read so far, without its line ending.
    pub fn first_line(&self) -> &[u8] {
        self.first_line
            .strip_suffix(b"\r")
            .unwrap_or(&self.first_line)
    }
}

/// The [`Overrun`] inside an I/O error, if that is what it holds.
pub fn overrun(err: &io::Error) -> Option<Overrun> {
    err.get_ref()?.downcast_ref::<Overrun>().copied()
}

impl<R: Read> Read for BoundedLines<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let got = self.inner.read(buf)?;
        for &b in &buf[..got] {
            if b == b'\n' {
                self.line += 1;
                self.in_line = 0;
                // A final newline does not start a line of its own, so count lines when
                // their first byte arrives.
                continue;
            }
            if self.in_line == 0 && self.line > self.max_lines {
                let max = self.max_lines;
                return Err(io::Error::new(
                    io::ErrorKind::InvalidData,
                    Overrun::TooManyLines { max },
                ));
            }
            self.in_line += 1;
            if self.in_line > MAX_LINE_BYTES {
                let line = self.line;
                return Err(io::Error::new(
                    io::ErrorKind::InvalidData,
                    Overrun::LongLine { line },
                ));
            }
            if self.line == 1 {
                self.first_line.push(b);
            }
        }
        Ok(got)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read_all(bytes: &[u8], max_lines: u64) -> io::Result<Vec<u8>> {
        let mut out = Vec::new();
        BoundedLines::new(bytes, max_lines).read_to_end(&mut out)?;
        Ok(out)
    }

    #[test]
    fn input_within_the_bounds_passes_unchanged() {
        let text = b"x,y\n1,2\n3,4\n";
        assert_eq!(read_all(text, 3).unwrap(), text);
        assert_eq!(read_all(b"x,y\n1,2\n3,4", 3).unwrap(), b"x,y\n1,2\n3,4");
    }

    #[test]
    fn endless_bytes_without_a_newline_stop_after_one_long_line() {
        let mut endless = BoundedLines::new(std::io::repeat(0).take(1 << 30), 10);
        let err = endless.read_to_end(&mut Vec::new()).unwrap_err();
        assert_eq!(overrun(&err), Some(Overrun::LongLine { line: 1 }));
    }

    #[test]
    fn one_line_too_many_is_refused() {
        let err = read_all(b"a\nb\nc\n", 2).unwrap_err();
        assert_eq!(overrun(&err), Some(Overrun::TooManyLines { max: 2 }));
    }

    #[test]
    fn the_first_line_is_kept_without_its_ending() {
        let mut r = BoundedLines::new(&b"# note\r\nx,y\n"[..], 5);
        std::io::copy(&mut r, &mut std::io::sink()).unwrap();
        assert_eq!(r.first_line(), b"# note");
    }
}
