//! Each pass as one `for_each_chunk` call: which arrays it writes (cut in lockstep into the
//! strategy's chunks), which it only reads, and the per-particle function it applies — one
//! file per model.

pub mod mueller;
pub mod wcsph;
