//! The instruction set the passes of a flat step run in: each pass ([`super::passes`]) is compiled twice,
//! for the baseline x86-64 the crate is built for (SSE2) and for x86-64-v3 (AVX2 and its companions), and
//! runs in the second when the CPU reports its features ([`v3`]).
//!
//! Why: with three-operand AVX instructions the pair loop needs fewer register copies and shuffles, and
//! the same passes ran 7–10 % faster (the whole crate built with `-C target-cpu=x86-64-v3`,
//! `examples/sphere_bed_speed`, one thread, 6 paired rounds: CPU-time ratios bed a 0.907,
//! b 0.911, c 0.931). Building the whole crate for x86-64-v3 would make a binary that stops on an older
//! CPU; choosing at run time keeps one binary for both.
//!
//! The same bits either way: Rust fuses no multiply and add unless asked (the passes never ask), and
//! every other operation is IEEE-exact in both instruction sets, so the checksums of the sphere beds'
//! final states are the same with and without the features (checked by
//! `tests/sphere_flat_paths.rs` on a machine that has them, and by the run above).

/// Whether this CPU has the features the passes' second build is compiled with: x86-64-v3's that the
/// compiler uses for this code (AVX2 with AVX and SSE4.2, and the bit instructions of BMI1/2, LZCNT and
/// POPCNT; not FMA), named in each `#[target_feature]` of [`super::passes`].
#[inline]
pub(super) fn v3() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2")
            && std::arch::is_x86_feature_detected!("bmi1")
            && std::arch::is_x86_feature_detected!("bmi2")
            && std::arch::is_x86_feature_detected!("lzcnt")
            && std::arch::is_x86_feature_detected!("popcnt")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}
