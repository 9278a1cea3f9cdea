#pragma once
// The epoch of a Repeat or Do body (dex::Engine): which run of the body, and which
// iteration of a Repeat within it, a node's counters and a message belong to.
namespace eamos::dex {

// A body's epoch counts its runs in the high bits and a Repeat's iterations in the low
// ones. A trigger from an earlier run is stale (that run was cancelled or is over); one
// from an earlier iteration of the same run is not: at a back arc everything of the
// iteration has ended except async work, which goes on in parallel and keeps its triggers.
inline constexpr int kIterationBits = 32;
inline long long run_of(long long epoch) { return epoch >> kIterationBits; }
inline long long next_run(long long epoch) { return (run_of(epoch) + 1) << kIterationBits; }

}  // namespace eamos::dex
