//! `--dump FILE.csv`: the final state. The first line is a comment saying what was dumped,
//! `# bench-sph dump: preset=cpp n=1000 step=1000` (see [`DumpInfo`]), then the header
//! `i,x,y,vx,vy,fx,fy,rho,p` and one row per particle. Every value is written with Rust's
//! shortest round-trip formatting (`{:?}`), so it parses back to the same bits; NaN is written
//! as `NaN` and infinities as `inf` / `-inf`.

use std::io::Write;

use crate::models::Preset;
use crate::sph::state::{FIELD_NAMES, State};

/// How a dump's first line starts.
pub const INFO_PREFIX: &str = "# bench-sph dump:";

/// What a dump records about the run it came from (its first line).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DumpInfo {
    /// The preset the state was simulated with.
    pub preset: Preset,
    /// The number of particles.
    pub n: usize,
    /// Steps done when it was dumped.
    pub step: usize,
}

impl DumpInfo {
    /// The first line of a dump, without its newline.
    pub fn line(&self) -> String {
        format!(
            "{INFO_PREFIX} preset={} n={} step={}",
            self.preset, self.n, self.step
        )
    }

    /// Reads a first line written by [`DumpInfo::line`]; `None` for any other line (an older
    /// dump, a hand-written file). Unknown `key=value` words are ignored.
    pub fn parse(line: &str) -> Option<DumpInfo> {
        let rest = line.trim_end().strip_prefix(INFO_PREFIX)?;
        let (mut preset, mut n, mut step) = (None, None, None);
        for word in rest.split_whitespace() {
            match word.split_once('=')? {
                ("preset", v) => preset = Preset::ALL.into_iter().find(|p| p.as_str() == v),
                ("n", v) => n = v.parse().ok(),
                ("step", v) => step = v.parse().ok(),
                _ => {}
            }
        }
        Some(DumpInfo {
            preset: preset?,
            n: n?,
            step: step?,
        })
    }
}

/// Writes `state` as CSV to `out`, after the line of `info` (whose `n` must be the state's).
pub fn write(state: &State, info: &DumpInfo, out: &mut impl Write) -> std::io::Result<()> {
    debug_assert_eq!(info.n, state.len());
    writeln!(out, "{}", info.line())?;
    writeln!(out, "i,{}", FIELD_NAMES.join(","))?;
    let fields = state.fields();
    for i in 0..state.len() {
        write!(out, "{i}")?;
        for field in fields {
            write!(out, ",{:?}", field[i])?;
        }
        writeln!(out)?;
    }
    out.flush()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_info_line_reads_back_and_other_lines_do_not() {
        let info = DumpInfo {
            preset: Preset::Cpp,
            n: 1000,
            step: 1000,
        };
        assert_eq!(info.line(), "# bench-sph dump: preset=cpp n=1000 step=1000");
        assert_eq!(DumpInfo::parse(&info.line()), Some(info));
        assert_eq!(DumpInfo::parse("# hello"), None);
        assert_eq!(DumpInfo::parse("i,x,y"), None);
        assert_eq!(
            DumpInfo::parse("# bench-sph dump: preset=python n=1 step=0"),
            None
        );
    }
}
