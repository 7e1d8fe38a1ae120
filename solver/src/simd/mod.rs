//! Which SIMD instructions the neighbour tests and Müller's force pass (with its update) run
//! on: a portable path (whatever the compiled target guarantees: SSE2 on x86-64, NEON on aarch64)
//! and, on x86-64, AVX2 and AVX-512, chosen at start-up from what the CPU has
//! ([`SimdPath::widest`]) or forced with `--simd`.
//!
//! The all-pairs search tests eight candidates per call ([`Lanes::near8`]); every pass that
//! searches runs inside [`Lanes::vectorize`], so the compiler may use the path's instructions for
//! the rest of the pass too, and so does the update loop of Müller's force pass (its wall clamps
//! written as selects, the compiler takes eight particles an instruction on AVX-512). On AVX-512
//! the grid of up to 4096 particles, and a larger grid's blocks of 16 candidates or more, scan a
//! row's candidates eight at a time and pack the hits in registers ([`Lanes::hits8`],
//! `vpcompressq`; a larger grid's sparse blocks measured faster one by one; the grid's
//! `scans_packed` decides). Otherwise, and on the other paths, the grid tests them one by one and
//! its search passes run as the target compiles them: a row holds only 3–12 candidates, and blocks
//! of eight whose hits are taken bit by bit measured slower there. Müller's force pass, on either
//! search, takes two neighbours at a time on the x86 paths, in four lanes ([`F64x4`], `quad.rs`),
//! which halves its divisions and square roots (measured 6 % faster; four pairs at a time in eight
//! lanes measured no faster again: the pass is not bound by the divider on this project's EPYC VM).
//!
//! Müller's density pass in the grid's cell order sums in eight lanes on every path, a row's
//! candidate k in lane k mod 8. On AVX-512 each row's candidates are tested eight at a time
//! ([`Lanes::near8_of`]), their contributions added lane by lane in two [`F64x4`] and the
//! neighbours kept packed with [`Lanes::compress8`]; the other paths take one candidate at a
//! time into its lane, which measured faster there (eight at a time in scalar code took
//! 26–44 % longer than the sequential sum; one at a time takes 3 % less).
//!
//! Every path computes the same bits. What is vectorised is lane-wise IEEE arithmetic in the
//! scalar code's order (`d = x_j − x_i`, `dx*dx + dy*dy`, then `< HSQ`): no fused multiply-add
//! (Rust never contracts), no reassociation, and each particle's sums still run in index order
//! over the hits a path reports. The portable path is the reference; the tests run every
//! strategy on every path this machine has and compare bits.
//!
//! The wider paths use `pulp` (safe wrappers over `std::arch` with run-time detection): no
//! `unsafe` here.

mod lanes;
mod quad;
mod quad_paths;

use std::sync::atomic::{AtomicU8, Ordering};

use serde::{Deserialize, Serialize};

#[cfg(test)]
pub(crate) use lanes::PackingPortable;
#[cfg(target_arch = "x86_64")]
pub use lanes::{Avx2, Avx512};
pub use lanes::{Hits8, Lanes, Near8, Portable, Row8};
pub use quad::{F64x4, Quad};

/// An instruction set the neighbour tests can run on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SimdPath {
    /// What the compiled target guarantees (SSE2 on x86-64): the reference.
    Portable,
    /// x86-64 AVX2 (4 lanes of f64), with the x86-64-v3 level's other features.
    Avx2,
    /// x86-64 AVX-512 (8 lanes of f64, bit masks), the x86-64-v4 level.
    Avx512,
}

impl SimdPath {
    /// Every path, narrowest first.
    pub const ALL: [SimdPath; 3] = [SimdPath::Portable, SimdPath::Avx2, SimdPath::Avx512];

    /// The name used on the command line, in `meta.json` and in `--json` output.
    pub fn as_str(self) -> &'static str {
        match self {
            SimdPath::Portable => "portable",
            SimdPath::Avx2 => "avx2",
            SimdPath::Avx512 => "avx512",
        }
    }

    /// Whether this CPU (and this build's target) can run the path.
    pub fn is_available(self) -> bool {
        self.lanes().is_some()
    }

    /// The paths this CPU can run, narrowest first (always at least `portable`).
    pub fn available() -> Vec<SimdPath> {
        Self::ALL.into_iter().filter(|p| p.is_available()).collect()
    }

    /// The widest path this CPU can run.
    pub fn widest() -> SimdPath {
        *Self::available()
            .last()
            .expect("the portable path is always available")
    }

    /// The path's lanes, or `None` when the CPU lacks its instructions.
    pub fn lanes(self) -> Option<AnyLanes> {
        match self {
            SimdPath::Portable => Some(AnyLanes::Portable(Portable)),
            #[cfg(target_arch = "x86_64")]
            SimdPath::Avx2 => Avx2::detect().map(AnyLanes::Avx2),
            #[cfg(target_arch = "x86_64")]
            SimdPath::Avx512 => Avx512::detect().map(AnyLanes::Avx512),
            #[cfg(not(target_arch = "x86_64"))]
            SimdPath::Avx2 | SimdPath::Avx512 => None,
        }
    }
}

impl std::fmt::Display for SimdPath {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// A path's lanes, checked available: what a run holds, matched once per pass with
/// [`with_lanes!`](crate::with_lanes) so the pass is compiled once per path.
#[derive(Debug, Clone, Copy)]
pub enum AnyLanes {
    /// See [`Portable`].
    Portable(Portable),
    /// See [`Avx2`].
    #[cfg(target_arch = "x86_64")]
    Avx2(Avx2),
    /// See [`Avx512`].
    #[cfg(target_arch = "x86_64")]
    Avx512(Avx512),
}

impl AnyLanes {
    /// Which path these are.
    pub fn path(self) -> SimdPath {
        match self {
            AnyLanes::Portable(_) => SimdPath::Portable,
            #[cfg(target_arch = "x86_64")]
            AnyLanes::Avx2(_) => SimdPath::Avx2,
            #[cfg(target_arch = "x86_64")]
            AnyLanes::Avx512(_) => SimdPath::Avx512,
        }
    }
}

/// Runs `$body` with `$l` bound to the concrete [`Lanes`] inside `$any` (an [`AnyLanes`]), so
/// that `$body` is compiled once per path and the path is picked once per call.
#[macro_export]
macro_rules! with_lanes {
    ($any:expr, $l:ident => $body:expr) => {
        match $any {
            $crate::simd::AnyLanes::Portable($l) => $body,
            #[cfg(target_arch = "x86_64")]
            $crate::simd::AnyLanes::Avx2($l) => $body,
            #[cfg(target_arch = "x86_64")]
            $crate::simd::AnyLanes::Avx512($l) => $body,
        }
    };
}

/// The process's path, set once at start-up by `--simd`; `u8::MAX` until then (the widest).
static CHOSEN: AtomicU8 = AtomicU8::new(u8::MAX);

/// The path `--simd` asked for, if it was given.
pub fn chosen() -> Option<SimdPath> {
    SimdPath::ALL
        .get(usize::from(CHOSEN.load(Ordering::Relaxed)))
        .copied()
}

/// The path new simulations use: the one [`choose`]n, else the widest this CPU runs.
pub fn current() -> SimdPath {
    match CHOSEN.load(Ordering::Relaxed) {
        0 => SimdPath::Portable,
        1 => SimdPath::Avx2,
        2 => SimdPath::Avx512,
        _ => SimdPath::widest(),
    }
}

/// Makes `path` the one new simulations use (the `--simd` flag).
///
/// # Errors
/// If this CPU cannot run it; the message names the paths it can.
pub fn choose(path: SimdPath) -> Result<(), Unavailable> {
    if !path.is_available() {
        return Err(Unavailable(path));
    }
    let code = SimdPath::ALL
        .iter()
        .position(|&p| p == path)
        .expect("listed");
    CHOSEN.store(code as u8, Ordering::Relaxed);
    Ok(())
}

/// A path this CPU cannot run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error(
    "--simd {0}: this CPU lacks its instructions (it can run: {paths})",
    paths = SimdPath::available().iter().map(|p| p.as_str()).collect::<Vec<_>>().join(", ")
)]
pub struct Unavailable(pub SimdPath);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn portable_is_always_available_and_the_widest_is_the_last_available() {
        assert!(SimdPath::Portable.is_available());
        let available = SimdPath::available();
        assert_eq!(available[0], SimdPath::Portable);
        assert_eq!(SimdPath::widest(), *available.last().unwrap());
        for p in SimdPath::ALL {
            assert_eq!(p.lanes().map(AnyLanes::path), p.is_available().then_some(p));
        }
    }

    #[test]
    fn an_unavailable_path_names_the_available_ones() {
        let msg = Unavailable(SimdPath::Avx512).to_string();
        assert!(msg.starts_with("--simd avx512: this CPU lacks"), "{msg}");
        assert!(msg.contains("portable"), "{msg}");
    }
}
