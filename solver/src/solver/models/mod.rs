//! Each model as the solver runs it, one file per model: its constants as a
//! [`Model`](super::model::Model) (search, lists, scratch, passes) and each pass as one
//! `for_each_chunk` call: which arrays it writes (cut in lockstep into the strategy's chunks),
//! which it only reads, and the per-particle function it applies.

pub mod mueller;
pub mod wcsph;
