//! The constants of the weakly compressible dam break, in SI units (m, s, kg), from its
//! resolution (see the book's "Physics" page, book/src/physics.md, and the module docs of
//! [`super`]).

use glam::DVec2;
use std::f64::consts::PI;

/// Width a of the water column, m (the column is a wide and 2a high; Martin & Moyce's
/// results are in units of a, so its value only sets the scale).
pub const COLUMN_WIDTH: f64 = 1.0;

/// Smallest and largest resolution R = a/dx any command accepts (R = 4 is the coarsest that
/// still has a fluid interior; R = 400 is 320 000 fluid particles, 40 000 steps to T = 3.4).
pub const RESOLUTIONS: std::ops::RangeInclusive<usize> = 4..=400;

/// The skin of the neighbour lists, in units of h: a list holds every particle within 2h + skin
/// of its own, so it serves until some particle has moved half the skin (see
/// [`crate::models::wcsph::kept`]). A thicker skin rebuilds less often but sums more pairs
/// that lie beyond 2h, each adding zero. On this project's EPYC VM (R = 40, 3000 steps, two
/// runs each) 0.1–0.2 h were the fastest of 0.05–0.45 h (within 4 % of each other; 0.3 h 6–10 %
/// slower, 0.05 h and 0.45 h over 15 %). At 0.15 h the lists reach 2.8 spacings, short of the
/// lattice's next shell (2.83), so they hold no more than 2h does there and
/// [`WCSPH_SLOTS`](crate::sph::neighbors::WCSPH_SLOTS) stays small.
pub const SKIN: f64 = 0.15;

/// Every constant of a step, derived once from the resolution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WcParams {
    /// R: particles across the column's width a.
    pub resolution: usize,
    /// Particle spacing dx = a / R, m.
    pub dx: f64,
    /// Smoothing length h = 1.3 dx, m.
    pub h: f64,
    /// Kernel support 2h, m: the neighbour search radius.
    pub support: f64,
    /// (2h)², m².
    pub support_sq: f64,
    /// The lists' skin, m ([`SKIN`]·h unless [`WcParams::with_skin`] set another).
    pub skin: f64,
    /// The lists' radius 2h + skin, m: the neighbour search's.
    pub list_radius: f64,
    /// The lists' radius squared, m².
    pub list_radius_sq: f64,
    /// The squared displacement since the lists were built past which they are built again:
    /// half the skin, less 1 % so that rounding in the distances cannot matter, squared, m².
    pub relist_sq: f64,
    /// Rest density ρ0, kg/m³.
    pub rho0: f64,
    /// Particle mass ρ0 dx², kg/m (2D).
    pub mass: f64,
    /// Gravity, m/s².
    pub gravity: DVec2,
    /// Speed of sound c0 = 10 √(2 g · 2a), m/s: ten times the fastest flow speed.
    pub c0: f64,
    /// Tait's B = ρ0 c0² / 7, Pa.
    pub tait_b: f64,
    /// Artificial viscosity α (Monaghan), fluid–fluid pairs only.
    pub alpha: f64,
    /// −α c0 h, m²/s: the artificial viscosity's numerator factor.
    pub viscosity: f64,
    /// 0.01 h², m²: keeps μ finite as r → 0.
    pub viscosity_eps_sq: f64,
    /// Density diffusion δ (Molteni–Colagrossi), fluid–fluid pairs only.
    pub delta: f64,
    /// Wendland C2 normalisation 7 / (4π h²), 1/m².
    pub kernel_norm: f64,
    /// Gradient factor 35 / (4π h⁴), 1/m⁴: ∇_a W_ab = −factor · (1 − q/2)³ · r_ab.
    pub gradient_norm: f64,
    /// 1 / h, 1/m: q = r / h is computed as r · (1/h).
    pub inv_h: f64,
    /// The time step's gravity bound 0.25 √(h / g), s.
    pub dt_gravity: f64,
    /// Particles 0..fluid move; the rest are the walls' fixed dummy particles.
    pub fluid: usize,
}

impl WcParams {
    /// The constants of resolution `resolution` for a state whose first `fluid` particles
    /// are fluid.
    pub fn new(resolution: usize, fluid: usize) -> WcParams {
        let dx = COLUMN_WIDTH / resolution as f64;
        let h = 1.3 * dx;
        let rho0 = 1000.0;
        let g = 9.81;
        let c0 = 10.0 * (2.0 * g * (2.0 * COLUMN_WIDTH)).sqrt();
        let h2 = h * h;
        let alpha = 0.02;
        WcParams {
            resolution,
            dx,
            h,
            support: 2.0 * h,
            support_sq: (2.0 * h) * (2.0 * h),
            skin: 0.0,
            list_radius: 0.0,
            list_radius_sq: 0.0,
            relist_sq: 0.0,
            rho0,
            mass: rho0 * dx * dx,
            gravity: DVec2::new(0.0, -g),
            c0,
            tait_b: rho0 * c0 * c0 / 7.0,
            alpha,
            viscosity: -alpha * c0 * h,
            viscosity_eps_sq: 0.01 * h2,
            delta: 0.1,
            kernel_norm: 7.0 / (4.0 * PI * h2),
            gradient_norm: 35.0 / (4.0 * PI * h2 * h2),
            inv_h: 1.0 / h,
            dt_gravity: 0.25 * (h / g).sqrt(),
            fluid,
        }
        .with_skin(SKIN)
    }

    /// The same constants with a skin of `skin` h: 0 builds the lists every step (any
    /// movement goes past half of no skin) at 2h, as a step without kept lists does.
    pub fn with_skin(self, skin: f64) -> WcParams {
        let skin = skin * self.h;
        let list_radius = self.support + skin;
        let relist = 0.99 * 0.5 * skin;
        WcParams {
            skin,
            list_radius,
            list_radius_sq: list_radius * list_radius,
            relist_sq: relist * relist,
            ..self
        }
    }

    /// Layers of wall particles: ⌈2h / dx⌉, so a fluid particle at the wall sees a full
    /// kernel support of wall.
    pub fn wall_layers(&self) -> usize {
        (self.support / self.dx - 1e-9).ceil() as usize
    }

    /// Pressure of density `rho` (Tait, γ = 7): B ((ρ/ρ0)⁷ − 1), Pa.
    #[inline]
    pub fn pressure(&self, rho: f64) -> f64 {
        let s = rho / self.rho0;
        let s2 = s * s;
        let s7 = (s2 * s2) * (s2 * s);
        self.tait_b * (s7 - 1.0)
    }

    /// Density of pressure `p` (the inverse of [`WcParams::pressure`]), kg/m³.
    #[inline]
    pub fn density(&self, p: f64) -> f64 {
        self.rho0 * (p / self.tait_b + 1.0).powf(1.0 / 7.0)
    }

    /// The time step for fastest fluid speed `v_max`:
    /// min(0.25 h / (c0 + v_max), 0.25 √(h/g)), s.
    #[inline]
    pub fn time_step(&self, v_max: f64) -> f64 {
        (0.25 * self.h / (self.c0 + v_max)).min(self.dt_gravity)
    }

    /// The Wendland C2 kernel at squared distance `r2` (zero at and beyond 2h), 1/m².
    #[inline]
    pub fn kernel(&self, r2: f64) -> f64 {
        let q = r2.sqrt() * self.inv_h;
        if q >= 2.0 {
            return 0.0;
        }
        let t = 1.0 - 0.5 * q;
        let t2 = t * t;
        self.kernel_norm * (t2 * t2) * (2.0 * q + 1.0)
    }

    /// The factor g with ∇_a W_ab = g · r_ab (r_ab = x_a − x_b) at squared distance `r2`:
    /// −35/(4π h⁴) (1 − q/2)³, zero at and beyond 2h, 1/m⁴.
    #[inline]
    pub fn gradient_factor(&self, r2: f64) -> f64 {
        let q = r2.sqrt() * self.inv_h;
        if q >= 2.0 {
            return 0.0;
        }
        let t = 1.0 - 0.5 * q;
        -self.gradient_norm * ((t * t) * t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_kernel_integrates_to_one_over_the_plane() {
        let prm = WcParams::new(40, 0);
        // Midpoint rule over rings out to 2h.
        let rings = 20_000;
        let dr = prm.support / rings as f64;
        let total: f64 = (0..rings)
            .map(|k| {
                let r = (k as f64 + 0.5) * dr;
                prm.kernel(r * r) * 2.0 * PI * r * dr
            })
            .sum();
        assert!((total - 1.0).abs() < 1e-6, "{total}");
    }

    #[test]
    fn the_gradient_is_the_kernels_derivative() {
        let prm = WcParams::new(20, 0);
        for q in [0.1, 0.5, 1.0, 1.5, 1.9] {
            let r = q * prm.h;
            let e = 1e-7 * prm.h;
            let dw_dr = (prm.kernel((r + e) * (r + e)) - prm.kernel((r - e) * (r - e))) / (2.0 * e);
            // ∇W = g r_ab, so dW/dr = g r.
            let g_r = prm.gradient_factor(r * r) * r;
            assert!(
                (dw_dr - g_r).abs() < 1e-6 * dw_dr.abs(),
                "q {q}: {dw_dr} vs {g_r}"
            );
        }
        assert_eq!(prm.gradient_factor(prm.support_sq), 0.0);
    }

    #[test]
    fn the_equation_of_state_inverts() {
        let prm = WcParams::new(40, 0);
        for p in [0.0, 1.0, 2e4, 1e5] {
            let rho = prm.density(p);
            assert!((prm.pressure(rho) - p).abs() < 1e-6 * prm.tait_b, "{p}");
        }
        assert_eq!(prm.pressure(prm.rho0), 0.0);
    }

    #[test]
    fn walls_are_as_thick_as_the_kernel_support() {
        let prm = WcParams::new(40, 0);
        assert_eq!(prm.wall_layers(), 3);
        assert!(prm.wall_layers() as f64 * prm.dx >= prm.support);
    }
}
