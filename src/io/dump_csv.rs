//! `--dump FILE.csv`: the final state, header `i,x,y,vx,vy,fx,fy,rho,p`. Every value is
//! written with Rust's shortest round-trip formatting (`{:?}`), so it parses back to the same
//! bits; NaN is written as `NaN` and infinities as `inf` / `-inf`.

use std::io::Write;

use crate::sph::state::{FIELD_NAMES, State};

/// Writes `state` as CSV to `out`.
pub fn write(state: &State, out: &mut impl Write) -> std::io::Result<()> {
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
