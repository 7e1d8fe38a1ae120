//! The passes a step is made of, named for benchmarks, traces and the models' schedules.

/// One pass of a step, for benchmarks and traces.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Pass {
    /// Müller: density and pressure (and each particle's neighbour list).
    Density,
    /// Müller: pressure, viscosity and gravity forces, and from them each particle's update
    /// (symplectic Euler and the walls), written apart until the pass has finished.
    Forces,
    /// WCSPH: each particle's own update (kick, density, drift).
    Integrate,
    /// WCSPH: the largest fluid speed, a reduction, and from it the time step.
    MaxSpeed,
    /// WCSPH: every particle's neighbour list.
    Neighbors,
    /// WCSPH: the walls' pressure and density from the fluid.
    Walls,
    /// WCSPH: each fluid particle's acceleration (and its neighbour list).
    Momentum,
    /// WCSPH: each fluid particle's density rate.
    Continuity,
}

impl Pass {
    /// Müller's two passes in step order.
    pub const MUELLER: [Pass; 2] = [Pass::Density, Pass::Forces];

    /// The WCSPH step's six passes in step order.
    pub const WCSPH: [Pass; 6] = [
        Pass::MaxSpeed,
        Pass::Neighbors,
        Pass::Walls,
        Pass::Momentum,
        Pass::Continuity,
        Pass::Integrate,
    ];

    /// Every pass: Müller's two, then WCSPH's (its update first).
    pub const ALL: [Pass; 8] = [
        Pass::Density,
        Pass::Forces,
        Pass::Integrate,
        Pass::MaxSpeed,
        Pass::Neighbors,
        Pass::Walls,
        Pass::Momentum,
        Pass::Continuity,
    ];

    /// Lower-case name, as in bench ids and traces.
    pub fn as_str(self) -> &'static str {
        match self {
            Pass::Density => "density",
            Pass::Forces => "forces",
            Pass::Integrate => "integrate",
            Pass::MaxSpeed => "max speed",
            Pass::Neighbors => "neighbours",
            Pass::Walls => "walls",
            Pass::Momentum => "momentum",
            Pass::Continuity => "continuity",
        }
    }
}
