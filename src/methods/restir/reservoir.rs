//! ReSTIR's resampling as plain Rust (Bitterli, Wyman, Pharr, Shirley, Lefohn & Jarosz 2020,
//! "Spatiotemporal reservoir resampling for real-time ray tracing with dynamic direct
//! lighting"): the CPU twin the GPU kernels are checked against, and what its statistical
//! tests hold to the target distribution.
//!
//! - Weighted reservoir sampling (the paper's Algorithm 2): a stream of weighted candidates,
//!   one kept with probability proportional to its weight.
//! - Resampled importance sampling (Talbot 2005; Algorithm 3) with candidates from several
//!   sources, each `M_s` candidates drawn from `p_s`, weighted by the balance heuristic over
//!   the sources and their counts (as RTXDI combines its light and BRDF samples): a candidate
//!   x weighs `w = p̂(x) / Σ_t M_t p_t(x)`, and the kept sample y has the unbiased contribution
//!   weight `W = w_sum / p̂(y)`. `f(y) W` is an unbiased estimate of `Σ_x f(x)` wherever
//!   `p̂ > 0` covers `f` and some source can draw every x with `f(x) ≠ 0`.
//! - The reservoirs' combination (Algorithm 4, the biased one: the merged `M` in the
//!   normalisation) and the unbiased one (Algorithm 6: `1 / Z`, Z the candidates of the
//!   inputs whose own target is non-zero at the chosen sample).

/// No sample (an empty reservoir).
pub const NONE: u32 = u32::MAX;

/// One pixel's reservoir: the kept sample, its target value where it was kept, the sum of
/// the candidates' weights, how many candidates it stands for, and its contribution weight.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reservoir {
    /// The kept VPL ([`NONE`] while empty).
    pub y: u32,
    /// p̂(y) at the reservoir's pixel.
    pub p_hat: f32,
    pub w_sum: f32,
    /// Candidates seen (a merged reservoir: the sum of its inputs' `m`, capped by the caller).
    pub m: f32,
    /// The unbiased contribution weight W (0 while empty): `f(y) W` estimates the sum.
    pub w: f32,
}

impl Default for Reservoir {
    fn default() -> Self {
        Self {
            y: NONE,
            p_hat: 0.0,
            w_sum: 0.0,
            m: 0.0,
            w: 0.0,
        }
    }
}

impl Reservoir {
    /// Algorithm 2's update: candidate `x` of weight `w` (target `p_hat` there) is kept with
    /// probability `w / w_sum` after it is added (`u` uniform in [0, 1)). Returns whether it
    /// was kept. Counts no candidate: callers count (`m`) as their algorithm says.
    pub fn update(&mut self, x: u32, w: f32, p_hat: f32, u: f32) -> bool {
        if !w.is_finite() || w <= 0.0 {
            return false;
        }
        self.w_sum += w;
        if u * self.w_sum < w {
            self.y = x;
            self.p_hat = p_hat;
            return true;
        }
        false
    }

    /// W = w_sum / (p̂(y) z): `z` = 1 for RIS with balance-heuristic weights, `m` for the
    /// biased combination, Z for the unbiased one. An empty or zero-target reservoir weighs 0.
    pub fn finalize(&mut self, z: f32) {
        self.w = if self.y != NONE && self.p_hat > 0.0 && z > 0.0 {
            self.w_sum / (self.p_hat * z)
        } else {
            0.0
        };
    }
}

/// A discrete distribution over the VPLs that can draw one and say any one's probability (a
/// candidate source of [`ris`]).
pub trait CandidateSource {
    /// A VPL drawn with `u` uniform in [0, 1), and its probability.
    fn sample(&self, u: f32) -> (u32, f32);
    /// The probability that [`CandidateSource::sample`] draws `x`.
    fn pdf(&self, x: u32) -> f32;
}

/// The VPLs in proportion to a weight each (their flux's luminance: the second candidate
/// source beside the light tree), drawn through the cumulative sums.
pub struct Weighted {
    cdf: Vec<f64>,
    weights: Vec<f32>,
    total: f64,
}

impl Weighted {
    /// A distribution over `weights` (negative ones count as 0; all 0: draws nothing).
    pub fn new(weights: &[f32]) -> Self {
        let weights: Vec<f32> = weights.iter().map(|&w| w.max(0.0)).collect();
        let mut cdf = Vec::with_capacity(weights.len());
        let mut total = 0.0f64;
        for &w in &weights {
            total += w as f64;
            cdf.push(total);
        }
        Self { cdf, weights, total }
    }
}

impl CandidateSource for Weighted {
    fn sample(&self, u: f32) -> (u32, f32) {
        if self.total <= 0.0 || self.total.is_nan() {
            return (NONE, 0.0);
        }
        let t = u as f64 * self.total;
        // The first entry whose cumulative sum exceeds t (zero weights are never drawn).
        let i = self.cdf.partition_point(|&c| c <= t).min(self.cdf.len() - 1);
        (i as u32, self.pdf(i as u32))
    }
    fn pdf(&self, x: u32) -> f32 {
        match self.weights.get(x as usize) {
            Some(&w) if self.total > 0.0 => (w as f64 / self.total) as f32,
            _ => 0.0,
        }
    }
}

/// RIS at one pixel: `M_s` candidates from each source `s` (`sources`: (source, M_s)), each
/// weighted `p̂(x) / Σ_t M_t p_t(x)` (the balance heuristic over sources and counts), one
/// kept; `m` counts the candidates, `w` is W = w_sum / p̂(y). `p_hat` is the target at this
/// pixel; `rng` yields uniform numbers in [0, 1).
pub fn ris(
    sources: &[(&dyn CandidateSource, u32)],
    p_hat: &dyn Fn(u32) -> f32,
    rng: &mut dyn FnMut() -> f32,
) -> Reservoir {
    let mut r = Reservoir::default();
    for &(src, count) in sources {
        for _ in 0..count {
            let (x, _) = src.sample(rng());
            r.m += 1.0;
            if x == NONE {
                continue;
            }
            let denom: f32 = sources.iter().map(|&(t, mt)| mt as f32 * t.pdf(x)).sum();
            let ph = p_hat(x);
            if denom > 0.0 {
                r.update(x, ph / denom, ph, rng());
            }
        }
    }
    r.finalize(1.0);
    r
}

/// Algorithm 4 (biased): the inputs (the pixel's own reservoir first, then the temporal or
/// spatial neighbours') merged at this pixel, each input weighing `p̂(y_i) W_i m_i` with this
/// pixel's target; `m` = Σ m_i; W = w_sum / (p̂(y) m). Biased where an input's sample cannot
/// light this pixel (its target 0 here) but its candidates count in m: the darkening that
/// [`combine_unbiased`] removes.
pub fn combine_biased(
    inputs: &[Reservoir],
    p_hat: &dyn Fn(u32) -> f32,
    rng: &mut dyn FnMut() -> f32,
) -> Reservoir {
    let mut s = merge(inputs, p_hat, rng);
    let m = s.m;
    s.finalize(m);
    s
}

/// Algorithm 6 (unbiased, 1/Z): as [`combine_biased`], but W = w_sum / (p̂(y) Z), Z the sum
/// of m_i over the inputs whose own pixel's target at the kept sample is above 0
/// (`p_hat_at[i]`: input i's pixel's target).
pub fn combine_unbiased(
    inputs: &[Reservoir],
    p_hat: &dyn Fn(u32) -> f32,
    p_hat_at: &[&dyn Fn(u32) -> f32],
    rng: &mut dyn FnMut() -> f32,
) -> Reservoir {
    let mut s = merge(inputs, p_hat, rng);
    let z: f32 = if s.y == NONE {
        0.0
    } else {
        inputs
            .iter()
            .zip(p_hat_at)
            .filter(|(_, f)| f(s.y) > 0.0)
            .map(|(r, _)| r.m)
            .sum()
    };
    s.finalize(z);
    s
}

/// The streaming merge both combinations share: each input's sample re-weighed by this
/// pixel's target, its W and its candidate count.
fn merge(inputs: &[Reservoir], p_hat: &dyn Fn(u32) -> f32, rng: &mut dyn FnMut() -> f32) -> Reservoir {
    let mut s = Reservoir::default();
    for r in inputs {
        s.m += r.m;
        if r.y == NONE {
            continue;
        }
        let ph = p_hat(r.y);
        s.update(r.y, ph * r.w * r.m, ph, rng());
    }
    s
}

/// Caps a reused reservoir's candidate count at `cap` (the paper's temporal M cap, 20 x the
/// current frame's candidates), scaling w_sum with it so that W is unchanged.
pub fn cap_m(r: &mut Reservoir, cap: f32) {
    if r.m > cap && r.m > 0.0 {
        r.w_sum *= cap / r.m;
        r.m = cap;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng, rngs::StdRng};

    /// Pearson's chi-square of `counts` against `expected` (bins with an expectation of at
    /// least 5), and its degrees of freedom.
    fn chi2(counts: &[u64], expected: &[f64]) -> (f64, usize) {
        let mut s = 0.0;
        let mut bins = 0usize;
        for (&c, &e) in counts.iter().zip(expected) {
            if e >= 5.0 {
                s += (c as f64 - e).powi(2) / e;
                bins += 1;
            } else {
                assert!(e > 0.0 || c == 0, "a bin of probability 0 was drawn");
            }
        }
        (s, bins.saturating_sub(1))
    }

    /// The 99.9% quantile of chi-square with `dof` degrees of freedom (Wilson-Hilferty).
    fn chi2_limit(dof: usize) -> f64 {
        let k = dof as f64;
        let z = 3.09;
        k * (1.0 - 2.0 / (9.0 * k) + z * (2.0 / (9.0 * k)).sqrt()).powi(3)
    }

    #[test]
    fn a_stream_keeps_each_candidate_in_proportion_to_its_weight() {
        let w = [0.5f32, 3.0, 0.0, 1.25, 7.0, 0.25, 2.0];
        let total: f64 = w.iter().map(|&x| x as f64).sum();
        let n = 200_000u64;
        let mut rng = StdRng::seed_from_u64(1);
        let mut counts = vec![0u64; w.len()];
        for _ in 0..n {
            let mut r = Reservoir::default();
            for (i, &x) in w.iter().enumerate() {
                r.update(i as u32, x, x, rng.random::<f32>());
            }
            counts[r.y as usize] += 1;
        }
        let expected: Vec<f64> = w.iter().map(|&x| n as f64 * x as f64 / total).collect();
        let (s, dof) = chi2(&counts, &expected);
        assert!(s < chi2_limit(dof), "chi2 {s:.1} with {dof} dof");
        assert_eq!(counts[2], 0, "a zero weight is never kept");
    }

    #[test]
    fn the_weighted_source_draws_by_its_weights_and_knows_its_pdf() {
        let w = [1.0f32, 0.0, 4.0, 2.5, 0.5];
        let src = Weighted::new(&w);
        let total: f32 = w.iter().sum();
        for (i, &x) in w.iter().enumerate() {
            assert!((src.pdf(i as u32) - x / total).abs() < 1e-6);
        }
        let n = 100_000u64;
        let mut rng = StdRng::seed_from_u64(2);
        let mut counts = vec![0u64; w.len()];
        for _ in 0..n {
            let (x, p) = src.sample(rng.random::<f32>());
            assert!((p - src.pdf(x)).abs() < 1e-7);
            counts[x as usize] += 1;
        }
        let expected: Vec<f64> = w.iter().map(|&x| n as f64 * (x / total) as f64).collect();
        let (s, dof) = chi2(&counts, &expected);
        assert!(s < chi2_limit(dof), "chi2 {s:.1} with {dof} dof");
        assert_eq!(Weighted::new(&[0.0, 0.0]).sample(0.3), (NONE, 0.0));
    }

    /// A toy pixel: 12 VPLs, f(x) the contribution, p̂ an approximation of it that is zero
    /// where f is (the unshadowed target of a shadowed f would be larger, never zero where f
    /// is not), two sources (one that misses half the VPLs, one by a "flux" weight).
    struct Toy {
        f: Vec<f32>,
        p_hat: Vec<f32>,
        flux: Weighted,
        half: Weighted,
    }

    fn toy() -> Toy {
        let f: Vec<f32> = (0..12)
            .map(|i| {
                if i % 5 == 3 {
                    0.0
                } else {
                    0.2 + (i as f32 * 0.7).sin().abs()
                }
            })
            .collect();
        let p_hat: Vec<f32> = f
            .iter()
            .enumerate()
            .map(|(i, &v)| {
                if v > 0.0 {
                    v * (1.0 + 0.3 * (i % 3) as f32)
                } else {
                    0.0
                }
            })
            .collect();
        let flux = Weighted::new(&(0..12).map(|i| 0.5 + (i % 4) as f32).collect::<Vec<_>>());
        let half = Weighted::new(
            &(0..12)
                .map(|i| if i < 6 { 1.0 + i as f32 } else { 0.0 })
                .collect::<Vec<_>>(),
        );
        Toy { f, p_hat, flux, half }
    }

    /// The mean of `n` estimates and its standard error.
    fn mean_se(n: usize, mut est: impl FnMut() -> f64) -> (f64, f64) {
        let (mut s, mut s2) = (0.0, 0.0);
        for _ in 0..n {
            let e = est();
            s += e;
            s2 += e * e;
        }
        let m = s / n as f64;
        (m, ((s2 / n as f64 - m * m).max(0.0) / n as f64).sqrt())
    }

    #[test]
    fn ris_with_two_sources_is_unbiased_and_its_error_falls_with_the_candidates() {
        let t = toy();
        let exact: f64 = t.f.iter().map(|&v| v as f64).sum();
        let mut rng = StdRng::seed_from_u64(3);
        let ph = |x: u32| t.p_hat[x as usize];
        let mut se_prev = f64::INFINITY;
        for m in [1u32, 4, 16] {
            let (mean, se) = mean_se(40_000, || {
                let mut u = || rng.random::<f32>();
                let r = ris(&[(&t.half, m), (&t.flux, m)], &ph, &mut u);
                if r.y == NONE {
                    0.0
                } else {
                    (t.f[r.y as usize] * r.w) as f64
                }
            });
            assert!(
                (mean - exact).abs() < 4.0 * se + 1e-9,
                "M {m}: mean {mean} vs {exact} (se {se})"
            );
            assert!(
                se < se_prev,
                "more candidates, less noise: M {m} se {se} after {se_prev}"
            );
            se_prev = se;
        }
        // One source alone that cannot draw half the VPLs: biased (it misses their light).
        let (mean, se) = mean_se(20_000, || {
            let mut u = || rng.random::<f32>();
            let r = ris(&[(&t.half, 8)], &ph, &mut u);
            if r.y == NONE {
                0.0
            } else {
                (t.f[r.y as usize] * r.w) as f64
            }
        });
        let reachable: f64 = t.f[..6].iter().map(|&v| v as f64).sum();
        assert!(
            (mean - reachable).abs() < 4.0 * se + 1e-9,
            "{mean} vs {reachable}"
        );
    }

    #[test]
    fn many_candidates_select_in_proportion_to_the_target() {
        // RIS's kept sample tends to p̂ / Σ p̂ as the candidates grow (chi-square at M = 512).
        let t = toy();
        let ph = |x: u32| t.p_hat[x as usize];
        let total: f64 = t.p_hat.iter().map(|&v| v as f64).sum();
        let mut rng = StdRng::seed_from_u64(4);
        let n = 20_000u64;
        let mut counts = vec![0u64; t.f.len()];
        for _ in 0..n {
            let mut u = || rng.random::<f32>();
            let r = ris(&[(&t.flux, 512)], &ph, &mut u);
            counts[r.y as usize] += 1;
        }
        let expected: Vec<f64> = t.p_hat.iter().map(|&v| n as f64 * v as f64 / total).collect();
        let (s, dof) = chi2(&counts, &expected);
        assert!(s < chi2_limit(dof), "chi2 {s:.1} with {dof} dof");
    }

    #[test]
    fn combining_keeps_the_estimate_unbiased_where_the_targets_agree_and_one_over_z_fixes_where_they_do_not()
    {
        let t = toy();
        let exact: f64 = t.f.iter().map(|&v| v as f64).sum();
        let ph = |x: u32| t.p_hat[x as usize];
        let mut rng = StdRng::seed_from_u64(5);
        // Four reservoirs of the same pixel merged (the temporal case with a still view).
        let (mean, se) = mean_se(20_000, || {
            let mut u = || rng.random::<f32>();
            let rs: Vec<Reservoir> = (0..4).map(|_| ris(&[(&t.flux, 4)], &ph, &mut u)).collect();
            let s = combine_biased(&rs, &ph, &mut u);
            if s.y == NONE {
                0.0
            } else {
                (t.f[s.y as usize] * s.w) as f64
            }
        });
        assert!(
            (mean - exact).abs() < 4.0 * se,
            "same targets: {mean} vs {exact} (se {se})"
        );
        // A neighbour whose target is zero on half the VPLs (another surface): its candidates
        // count in m for the biased combination (darker), not in Z for the unbiased one.
        let other: Vec<f32> = t
            .p_hat
            .iter()
            .enumerate()
            .map(|(i, &v)| if i % 2 == 0 { v } else { 0.0 })
            .collect();
        let ph_other = |x: u32| other[x as usize];
        let mut run = |unbiased: bool| {
            mean_se(30_000, || {
                let mut u = || rng.random::<f32>();
                let own = ris(&[(&t.flux, 4)], &ph, &mut u);
                let nb = ris(&[(&t.flux, 4)], &ph_other, &mut u);
                let s = if unbiased {
                    combine_unbiased(&[own, nb], &ph, &[&ph, &ph_other], &mut u)
                } else {
                    combine_biased(&[own, nb], &ph, &mut u)
                };
                if s.y == NONE {
                    0.0
                } else {
                    (t.f[s.y as usize] * s.w) as f64
                }
            })
        };
        let (unb, se_u) = run(true);
        assert!(
            (unb - exact).abs() < 4.0 * se_u,
            "1/Z: {unb} vs {exact} (se {se_u})"
        );
        let (bia, se_b) = run(false);
        assert!(
            bia < exact - 4.0 * se_b,
            "the biased combination darkens: {bia} vs {exact}"
        );
    }

    #[test]
    fn capping_m_keeps_w() {
        let mut r = Reservoir {
            y: 3,
            p_hat: 0.5,
            w_sum: 40.0,
            m: 80.0,
            w: 0.0,
        };
        r.finalize(r.m);
        let w = r.w;
        cap_m(&mut r, 20.0);
        assert_eq!(r.m, 20.0);
        r.finalize(r.m);
        assert!((r.w - w).abs() < 1e-6 * w);
    }
}
