//! bench-sph library.
