//! Image error metrics between a method's image and a reference of the same size.
//!
//! - RMSE on linear radiance (all three channels, W m^-2 sr^-1), and relative RMSE = RMSE /
//!   mean of the reference (unitless; comparable across scenes and exposures).
//! - SSIM (Wang et al. 2004: 11 x 11 Gaussian window, sigma 1.5, K1 = 0.01, K2 = 0.03,
//!   L = 1) on the luminance of both images as the workbench displays them (exposure 2^EV,
//!   tonemap, sRGB encoding), so that it judges what a viewer sees.
//! - Mean ratio (method mean / reference mean): a bias indicator.
//! - FLIP (Andersson et al. 2020, "FLIP: A Difference Evaluator for Alternating Images"):
//!   the mean of NVIDIA's LDR-FLIP error map (the `nv-flip` crate, the reference C++ code)
//!   of both images as displayed (sRGB 8-bit), at 67 pixels per degree (0.7 m from a 0.7 m
//!   wide 4K monitor).
//!
//! Pixels without geometry (alpha 0 in the reference's position, passed as a mask) can be
//! left out; by default every pixel counts.

use glam::Vec3;

use crate::base::{
    display::{self, Tonemap},
    image::ImageF32,
};

#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Metrics {
    pub rmse: f64,
    pub relative_rmse: f64,
    pub ssim: f64,
    pub mean_ratio: f64,
    pub reference_mean: f64,
    /// Mean LDR-FLIP of the displayed images (0 = identical, 1 = maximal).
    pub flip: f64,
}

/// The displayed sRGB 8-bit RGB of an image (the display pass's encoding).
fn displayed_rgb8(img: &ImageF32, exposure_ev: f32, tonemap: Tonemap) -> Vec<u8> {
    img.pixels
        .iter()
        .flat_map(|p| {
            let e = display::encode(*p, exposure_ev, tonemap);
            [e[0], e[1], e[2]]
        })
        .collect()
}

/// Mean LDR-FLIP of `image` against `reference` (same size) as displayed.
pub fn flip(image: &ImageF32, reference: &ImageF32, exposure_ev: f32, tonemap: Tonemap) -> f64 {
    let (w, h) = (reference.width, reference.height);
    if w == 0 || h == 0 || (image.width, image.height) != (w, h) {
        return f64::NAN;
    }
    let r = nv_flip::FlipImageRgb8::with_data(w, h, &displayed_rgb8(reference, exposure_ev, tonemap));
    let t = nv_flip::FlipImageRgb8::with_data(w, h, &displayed_rgb8(image, exposure_ev, tonemap));
    let err = nv_flip::flip(r, t, nv_flip::DEFAULT_PIXELS_PER_DEGREE);
    nv_flip::FlipPool::from_image(&err).mean() as f64
}

/// The pixels of `img` in [x0, x1) x [y0, y1) (clamped to the image).
pub fn crop(img: &ImageF32, rect: [u32; 4]) -> ImageF32 {
    let [x0, y0, x1, y1] = rect;
    let (x1, y1) = (x1.min(img.width), y1.min(img.height));
    let (x0, y0) = (x0.min(x1), y0.min(y1));
    let mut pixels = Vec::with_capacity(((x1 - x0) * (y1 - y0)) as usize);
    for y in y0..y1 {
        for x in x0..x1 {
            pixels.push(img.get(x, y));
        }
    }
    ImageF32 {
        width: x1 - x0,
        height: y1 - y0,
        pixels,
    }
}

fn rgb(p: &[f32; 4]) -> Vec3 {
    Vec3::new(p[0], p[1], p[2])
}

/// RMSE over the RGB channels of the pixels where `mask` is true (all if None).
pub fn rmse(a: &ImageF32, b: &ImageF32, mask: Option<&[bool]>) -> f64 {
    let mut sum = 0.0f64;
    let mut n = 0usize;
    for (i, (pa, pb)) in a.pixels.iter().zip(&b.pixels).enumerate() {
        if mask.is_some_and(|m| !m[i]) {
            continue;
        }
        let d = rgb(pa) - rgb(pb);
        sum += (d.x as f64).powi(2) + (d.y as f64).powi(2) + (d.z as f64).powi(2);
        n += 3;
    }
    (sum / n.max(1) as f64).sqrt()
}

fn mean_rgb(a: &ImageF32, mask: Option<&[bool]>) -> f64 {
    let mut sum = 0.0f64;
    let mut n = 0usize;
    for (i, p) in a.pixels.iter().enumerate() {
        if mask.is_some_and(|m| !m[i]) {
            continue;
        }
        sum += (p[0] + p[1] + p[2]) as f64;
        n += 3;
    }
    sum / n.max(1) as f64
}

/// Display luminance in [0, 1] of every pixel (exposure, tonemap, sRGB).
pub fn display_luminance(a: &ImageF32, exposure_ev: f32, tonemap: Tonemap) -> Vec<f32> {
    par_map(a.pixels.len(), |i| {
        let e = display::encode(a.pixels[i], exposure_ev, tonemap);
        display::luminance(Vec3::new(e[0] as f32, e[1] as f32, e[2] as f32) / 255.0)
    })
}

/// Threads for the metrics (the machine's cores, at most 16).
fn threads() -> usize {
    std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(16)
}

/// `f(i)` for i in 0..n, computed on [`threads`] threads in contiguous chunks, in order.
fn par_map<T: Send>(n: usize, f: impl Fn(usize) -> T + Sync) -> Vec<T> {
    let t = threads();
    if t <= 1 || n < 4096 {
        return (0..n).map(f).collect();
    }
    let chunk = n.div_ceil(t);
    let f = &f;
    std::thread::scope(|s| {
        let parts: Vec<_> = (0..n)
            .step_by(chunk)
            .map(|a| s.spawn(move || (a..(a + chunk).min(n)).map(f).collect::<Vec<T>>()))
            .collect();
        parts
            .into_iter()
            .flat_map(|p| p.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
            .collect()
    })
}

/// Mean SSIM of two grey images in [0, 1] (Wang et al. 2004, Gaussian window 11, sigma 1.5);
/// windows are clipped at the borders. The five weighted moments (mu_a, mu_b, E[a^2],
/// E[b^2], E[ab]) are blurred together, rows and then columns in parallel.
pub fn ssim(a: &[f32], b: &[f32], w: usize, h: usize) -> f64 {
    const R: i32 = 5;
    let g: Vec<f64> = (-R..=R)
        .map(|i| (-(i * i) as f64 / (2.0 * 1.5 * 1.5)).exp())
        .collect();
    let (c1, c2) = ((0.01f64).powi(2), (0.03f64).powi(2));
    let moments = |i: usize| {
        let (x, y) = (a[i] as f64, b[i] as f64);
        [x, y, x * x, y * y, x * y]
    };
    // Horizontal pass: per pixel, the five moments blurred along its row.
    let tmp: Vec<[f64; 5]> = par_map(w * h, |i| {
        let (x, y) = (i % w, i / w);
        let (mut s, mut ws) = ([0.0f64; 5], 0.0);
        for (k, gk) in g.iter().enumerate() {
            let xx = x as i32 + k as i32 - R;
            if xx >= 0 && (xx as usize) < w {
                let m = moments(y * w + xx as usize);
                for c in 0..5 {
                    s[c] += gk * m[c];
                }
                ws += gk;
            }
        }
        s.map(|v| v / ws)
    });
    // Vertical pass and the SSIM of each pixel.
    let per_pixel: Vec<f64> = par_map(w * h, |i| {
        let (x, y) = (i % w, i / w);
        let (mut s, mut ws) = ([0.0f64; 5], 0.0);
        for (k, gk) in g.iter().enumerate() {
            let yy = y as i32 + k as i32 - R;
            if yy >= 0 && (yy as usize) < h {
                let m = tmp[yy as usize * w + x];
                for c in 0..5 {
                    s[c] += gk * m[c];
                }
                ws += gk;
            }
        }
        let [ma, mb, aa, bb, ab] = s.map(|v| v / ws);
        let (va, vb) = ((aa - ma * ma).max(0.0), (bb - mb * mb).max(0.0));
        let cov = ab - ma * mb;
        ((2.0 * ma * mb + c1) * (2.0 * cov + c2)) / ((ma * ma + mb * mb + c1) * (va + vb + c2))
    });
    per_pixel.iter().sum::<f64>() / (w * h).max(1) as f64
}

/// Splits the error of F independent frames against a reference into bias and noise:
/// E[mse of a frame] = b^2 + s^2 and E[mse of the frames' mean] = b^2 + s^2 / F, so
///   b^2 = (F mse_mean - mean(mse_frame)) / (F - 1),  s^2 = mean(mse_frame) - b^2,
/// both unbiased. Returns (b, s) as RMSEs (negative estimates, possible from noise, clamp to
/// 0); NaN with fewer than 2 frames.
pub fn bias_noise(frame_mse: &[f64], mean_mse: f64) -> (f64, f64) {
    let f = frame_mse.len() as f64;
    if frame_mse.len() < 2 {
        return (f64::NAN, f64::NAN);
    }
    let m = frame_mse.iter().sum::<f64>() / f;
    let b2 = (f * mean_mse - m) / (f - 1.0);
    (b2.max(0.0).sqrt(), (m - b2).max(0.0).sqrt())
}

/// Every metric of `image` against `reference` (same size), SSIM on the display transform.
pub fn compare(image: &ImageF32, reference: &ImageF32, exposure_ev: f32, tonemap: Tonemap) -> Metrics {
    Metrics {
        flip: flip(image, reference, exposure_ev, tonemap),
        ..compare_without_flip(image, reference, exposure_ev, tonemap)
    }
}

/// [`compare`] without FLIP (NaN), the costly one: what the harness computes per frame.
pub fn compare_without_flip(
    image: &ImageF32,
    reference: &ImageF32,
    exposure_ev: f32,
    tonemap: Tonemap,
) -> Metrics {
    let rm = rmse(image, reference, None);
    let mean_ref = mean_rgb(reference, None);
    let mean_img = mean_rgb(image, None);
    let (w, h) = (reference.width as usize, reference.height as usize);
    let s = ssim(
        &display_luminance(image, exposure_ev, tonemap),
        &display_luminance(reference, exposure_ev, tonemap),
        w,
        h,
    );
    Metrics {
        rmse: rm,
        relative_rmse: if mean_ref > 0.0 { rm / mean_ref } else { f64::NAN },
        ssim: s,
        mean_ratio: if mean_ref > 0.0 {
            mean_img / mean_ref
        } else {
            f64::NAN
        },
        reference_mean: mean_ref,
        flip: f64::NAN,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bias_and_noise_are_recovered_from_independent_frames() {
        // Frames = reference + bias b + Gaussian noise of deviation s (exactly known), many
        // pixels: the estimates land within a few percent.
        let (w, h, frames, b, s) = (64u32, 64u32, 8usize, 0.03f32, 0.1f32);
        let reference = img(w, h, |x, y| 0.2 + 0.01 * ((x + 3 * y) % 7) as f32);
        let mut state = 0x1234_5678u32;
        let mut uniform = move || {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            (state as f64 + 0.5) / 4_294_967_296.0
        };
        let mut gauss = move || {
            let (u1, u2) = (uniform(), uniform());
            ((-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()) as f32
        };
        let mut mean = reference.clone();
        mean.pixels.iter_mut().for_each(|p| *p = [0.0; 4]);
        let mut mses = Vec::new();
        for _ in 0..frames {
            let mut f = reference.clone();
            for p in &mut f.pixels {
                for c in &mut p[..3] {
                    *c += b + s * gauss();
                }
            }
            mses.push(rmse(&f, &reference, None).powi(2));
            for (m, p) in mean.pixels.iter_mut().zip(&f.pixels) {
                for c in 0..3 {
                    m[c] += p[c] / frames as f32;
                }
            }
        }
        let (eb, es) = bias_noise(&mses, rmse(&mean, &reference, None).powi(2));
        assert!((eb / b as f64 - 1.0).abs() < 0.05, "bias {eb} vs {b}");
        assert!((es / s as f64 - 1.0).abs() < 0.02, "noise {es} vs {s}");
        // Unbiased frames: the bias estimate is noise-sized, far below the noise.
        let (eb0, _) = bias_noise(&[0.01, 0.01], 0.005);
        assert_eq!(eb0, 0.0);
        assert!(bias_noise(&[0.01], 0.01).0.is_nan());
    }

    #[test]
    fn flip_is_zero_for_equal_images_and_grows_with_the_difference() {
        let base = img(48, 32, |x, y| 0.05 + 0.01 * ((x * 7 + y * 3) % 11) as f32);
        assert_eq!(flip(&base, &base, 0.0, Tonemap::Aces), 0.0);
        let noisy = |amp: f32| {
            img(48, 32, |x, y| {
                let n = (((x * 92_821 + y * 68_917) % 1000) as f32 / 1000.0 - 0.5) * amp;
                (0.05 + 0.01 * ((x * 7 + y * 3) % 11) as f32 + n).max(0.0)
            })
        };
        let (small, large) = (
            flip(&noisy(0.02), &base, 0.0, Tonemap::Aces),
            flip(&noisy(0.2), &base, 0.0, Tonemap::Aces),
        );
        assert!(
            small > 0.0 && large > small && large <= 1.0,
            "FLIP {small} then {large}"
        );
        let c = crop(&base, [10, 5, 20, 30]);
        assert_eq!((c.width, c.height), (10, 25));
        assert_eq!(c.get(0, 0), base.get(10, 5));
    }

    fn img(w: u32, h: u32, f: impl Fn(u32, u32) -> f32) -> ImageF32 {
        ImageF32 {
            width: w,
            height: h,
            pixels: (0..h)
                .flat_map(|y| (0..w).map(move |x| (x, y)))
                .map(|(x, y)| {
                    let v = f(x, y);
                    [v, v, v, 1.0]
                })
                .collect(),
        }
    }

    #[test]
    fn rmse_and_ratio_by_hand() {
        let a = img(4, 4, |_, _| 1.0);
        let b = img(4, 4, |_, _| 0.5);
        assert!((rmse(&a, &b, None) - 0.5).abs() < 1e-12);
        let m = compare(&a, &b, 0.0, Tonemap::Clamp);
        assert!((m.relative_rmse - 1.0).abs() < 1e-9);
        assert!((m.mean_ratio - 2.0).abs() < 1e-9);
        let mask: Vec<bool> = (0..16).map(|i| i < 8).collect();
        let c = img(4, 4, |_, y| if y < 2 { 0.5 } else { 9.0 });
        assert_eq!(rmse(&c, &b, Some(&mask)), 0.0);
    }

    #[test]
    fn ssim_is_one_for_equal_images_and_drops_with_noise() {
        let (w, h) = (48, 40);
        let a: Vec<f32> = (0..w * h)
            .map(|i| ((i % w) as f32 / w as f32) * 0.8 + 0.1)
            .collect();
        assert!((ssim(&a, &a, w, h) - 1.0).abs() < 1e-9);
        let mut s = 1u32;
        let noisy: Vec<f32> = a
            .iter()
            .map(|v| {
                s ^= s << 13;
                s ^= s >> 17;
                s ^= s << 5;
                (v + ((s >> 8) as f32 / (1 << 24) as f32 - 0.5) * 0.4).clamp(0.0, 1.0)
            })
            .collect();
        let q = ssim(&a, &noisy, w, h);
        assert!(q < 0.9 && q > 0.0, "{q}");
        // A constant offset keeps the structure: SSIM stays high but below 1.
        let shifted: Vec<f32> = a.iter().map(|v| v + 0.05).collect();
        let q2 = ssim(&a, &shifted, w, h);
        assert!(q2 > 0.95 && q2 < 1.0, "{q2}");
    }

    /// The single-threaded SSIM the workbench used before the parallel one (each moment
    /// blurred on its own): the reference the parallel version must equal.
    fn ssim_serial(a: &[f32], b: &[f32], w: usize, h: usize) -> f64 {
        const R: i32 = 5;
        let g: Vec<f64> = (-R..=R)
            .map(|i| (-(i * i) as f64 / (2.0 * 1.5 * 1.5)).exp())
            .collect();
        let (c1, c2) = ((0.01f64).powi(2), (0.03f64).powi(2));
        let blur = |f: &dyn Fn(usize) -> f64| -> Vec<f64> {
            let mut tmp = vec![0.0; w * h];
            for y in 0..h {
                for x in 0..w {
                    let (mut s, mut ws) = (0.0, 0.0);
                    for (k, gk) in g.iter().enumerate() {
                        let xx = x as i32 + k as i32 - R;
                        if xx >= 0 && (xx as usize) < w {
                            s += gk * f(y * w + xx as usize);
                            ws += gk;
                        }
                    }
                    tmp[y * w + x] = s / ws;
                }
            }
            let mut out = vec![0.0; w * h];
            for y in 0..h {
                for x in 0..w {
                    let (mut s, mut ws) = (0.0, 0.0);
                    for (k, gk) in g.iter().enumerate() {
                        let yy = y as i32 + k as i32 - R;
                        if yy >= 0 && (yy as usize) < h {
                            s += gk * tmp[yy as usize * w + x];
                            ws += gk;
                        }
                    }
                    out[y * w + x] = s / ws;
                }
            }
            out
        };
        let ma = blur(&|i| a[i] as f64);
        let mb = blur(&|i| b[i] as f64);
        let aa = blur(&|i| (a[i] as f64).powi(2));
        let bb = blur(&|i| (b[i] as f64).powi(2));
        let ab = blur(&|i| a[i] as f64 * b[i] as f64);
        let mut total = 0.0;
        for i in 0..w * h {
            let (va, vb) = ((aa[i] - ma[i] * ma[i]).max(0.0), (bb[i] - mb[i] * mb[i]).max(0.0));
            let cov = ab[i] - ma[i] * mb[i];
            total += ((2.0 * ma[i] * mb[i] + c1) * (2.0 * cov + c2))
                / ((ma[i] * ma[i] + mb[i] * mb[i] + c1) * (va + vb + c2));
        }
        total / (w * h).max(1) as f64
    }

    #[test]
    fn parallel_ssim_and_luminance_equal_the_serial_reference() {
        // Large enough for the parallel path (>= 4096 pixels), odd sizes.
        let (w, h) = (131usize, 77usize);
        let mut state = 0x2545_f491u32;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            state as f32 / u32::MAX as f32
        };
        let a: Vec<f32> = (0..w * h).map(|_| next()).collect();
        let b: Vec<f32> = a.iter().map(|v| (v + 0.2 * next()).min(1.0)).collect();
        let p = ssim(&a, &b, w, h);
        let s = ssim_serial(&a, &b, w, h);
        assert!(
            (p - s).abs() <= 1e-12 * s.abs().max(1.0),
            "parallel {p} vs serial {s}"
        );
        let image = img(w as u32, h as u32, |x, y| (x * y) as f32 * 1e-3);
        let lum = display_luminance(&image, 0.0, Tonemap::default());
        for (i, px) in image.pixels.iter().enumerate() {
            let e = display::encode(*px, 0.0, Tonemap::default());
            let want = display::luminance(Vec3::new(e[0] as f32, e[1] as f32, e[2] as f32) / 255.0);
            assert_eq!(lum[i], want, "pixel {i}");
        }
    }
}
