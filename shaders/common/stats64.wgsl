// 64-bit frame counters as pairs of u32 words (low, high) in an atomic array.
// Contract: the includer declares `stats: array<atomic<u32>>` (any binding).
// Twin of the readers: `w[i] as u64 | (w[i + 1] as u64) << 32` (LcStats, LiStats, ...).

// Adds v to the counter at words (i, i + 1), carrying into the high word.
fn stats_add64(i: u32, v: u32) {
    let old = atomicAdd(&stats[i], v);
    if old > 0xffffffffu - v {
        atomicAdd(&stats[i + 1u], 1u);
    }
}
