#!/usr/bin/env python3
"""Independent check of lightcut-workbench's direct (and N-bounce indirect) light with Mitsuba 3.

Inputs:
  --scene-dir  output of `lightcut-workbench export-scene` (scene.json, mesh_*.ply, textures/)
  --ours       output of `lightcut-workbench render` (direct.exr, optionally indirect.exr)

Mitsuba renders the same scene (two-sided diffuse BSDFs with the exported albedos x sRGB-decoded
textures, a `directional` emitter with the exported travel direction and irradiance, a
`look_at` pinhole sensor, box pixel filter, `path` integrator):
  direct   = path(max_depth=2)
  indirect = path(max_depth=N+2) - path(max_depth=2), same seed  (only with --indirect;
             N = --bounces, default 1; ours rendered with `render --bounces N`); with
             --brdf ggx the `lightcut_first_glossy` integrator instead: GGX at the camera's
             hit, N diffuse (Lambert, base colour) bounces to the sun beyond, as our VPLs
The image is rendered in --splits independent parts (different seeds, spp/splits each) whose
spread gives the standard error of Mitsuba's image mean and region means.

Outputs in --out: mitsuba_direct.exr (+ mitsuba_indirect.exr), compare_<part>.png
(ours | Mitsuba | relative difference, false colour), report.md, report.json; a short summary
on stdout. Needs only `mitsuba` and `numpy` (pip install mitsuba numpy).

See docs/mitsuba_check.md for the commands and the measured numbers.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
from pathlib import Path

import numpy as np


def parse_args(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--scene-dir", required=True, type=Path, help="export-scene output folder")
    p.add_argument("--ours", required=True, type=Path, help="render output folder (direct.exr, indirect.exr)")
    p.add_argument("--width", type=int, required=True)
    p.add_argument("--height", type=int, required=True)
    p.add_argument("--spp", type=int, default=256, help="samples per pixel for the direct render (total over splits)")
    p.add_argument("--indirect-spp", type=int, default=None,
                   help="samples per pixel for the two indirect renders (default: --spp)")
    p.add_argument("--indirect", action="store_true", help="also compare the indirect light (needs ours/indirect.exr)")
    p.add_argument("--brdf", choices=["lambert", "ggx", "principled"], default="lambert",
                   help="ggx: the workbench's GGX BRDF (as a Python BSDF) with the exported metallic / roughness; "
                        "ours rendered with `render --brdf ggx`. principled: Mitsuba's own `principled` BSDF with "
                        "the same base colour / metallic / roughness (specular 0.5 = F0 0.04, no tint, sheen, "
                        "clearcoat or transmission) against ours with GGX: a comparison of the models (Disney "
                        "diffuse, separable Smith masking), direct light only")
    p.add_argument("--bounces", type=int, default=1,
                   help="diffuse bounces of the indirect part: path max_depth = bounces + 2 (ours: render --bounces)")
    p.add_argument("--variant", default="scalar_rgb", help="Mitsuba variant (scalar_rgb, llvm_ad_rgb, ...)")
    p.add_argument("--sampler", default="ldsampler", choices=["ldsampler", "independent", "stratified", "multijitter"])
    p.add_argument("--splits", type=int, default=4,
                   help="independent renders (different seeds) averaged; their spread estimates Mitsuba's noise")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--grid", type=int, default=4, help="region grid (N x N blocks) for region means")
    p.add_argument("--flip-v", action="store_true",
                   help="use v' = 1 - v for textures (not needed: Mitsuba 3's bitmap puts v = 0 at the top "
                        "row and its PLY loader keeps v, like glTF)")
    p.add_argument("--reuse-mitsuba", type=Path, default=None,
                   help="take Mitsuba's split renders from an earlier --out folder (same scene, size, spp, "
                        "splits, seed, variant, sampler) instead of rendering again")
    p.add_argument("--self-check", action="store_true",
                   help="check `lightcut_first_glossy` itself: with --brdf lambert its one-bounce image equals "
                        "path(max_depth=3) - path(max_depth=2) (same scene, --spp); prints both means and exits")
    p.add_argument("--out", required=True, type=Path)
    return p.parse_args(argv)


# ----------------------------------------------------------------------------------------------
# Scene construction


def srgb_to_linear(c8: np.ndarray) -> np.ndarray:
    """The exact sRGB EOTF (IEC 61966-2-1), as the renderer's Rgba8UnormSrgb sampling does."""
    x = c8.astype(np.float64) / 255.0
    return np.where(x <= 0.04045, x / 12.92, ((x + 0.055) / 1.055) ** 2.4)


def load_texture(mi, path: Path, factor, flip_v: bool):
    """Linear RGB albedo texture = factor x sRGB-decoded image, as a raw float mi.Bitmap."""
    bmp = mi.Bitmap(str(path))
    arr = np.array(bmp)
    if arr.dtype != np.uint8:
        raise SystemExit(f"error: texture {path} is not 8-bit (got {arr.dtype}); export-scene writes RGBA8 PNGs")
    if arr.ndim == 2:
        arr = arr[:, :, None]
    if arr.shape[2] == 1 or arr.shape[2] == 2:  # grey or grey+alpha
        arr = np.repeat(arr[:, :, :1], 3, axis=2)
    rgb = srgb_to_linear(arr[:, :, :3]) * np.asarray(factor, dtype=np.float64)[None, None, :]
    if flip_v:
        rgb = rgb[::-1]
    return mi.Bitmap(np.ascontiguousarray(rgb.astype(np.float32)), mi.Bitmap.PixelFormat.RGB)


def register_lightcut_ggx(mi):
    """Registers `lightcut_ggx`: the workbench's GGX BRDF (shaders/common/brdf.wgsl) as a
    Mitsuba BSDF, so that `--brdf ggx` compares the same BRDF (Mitsuba's roughconductor /
    principled differ in their Fresnel and diffuse terms). Sampling: half cosine, half GGX
    half-vectors (the pdf is the mixture's); eval / pdf in the local shading frame."""
    import drjit as dr

    class LightcutGgx(mi.BSDF):
        def __init__(self, props):
            mi.BSDF.__init__(self, props)
            self.base = props.get_texture("base")
            self.metallic = props["metallic"]
            self.roughness = props["roughness"]
            flags = (mi.BSDFFlags.DiffuseReflection | mi.BSDFFlags.GlossyReflection
                     | mi.BSDFFlags.FrontSide)
            self.m_components = [flags]
            self.m_flags = flags

        def _alpha(self):
            return max(self.roughness * self.roughness, 0.002)

        def _d(self, h):
            """GGX's D(h) and cos(theta_h) (h in the local frame)."""
            nh = dr.maximum(mi.Frame3f.cos_theta(h), 0.0)
            a2 = self._alpha() ** 2
            q = nh * nh * (a2 - 1.0) + 1.0
            return a2 / (dr.pi * q * q), nh

        def _f(self, si, wi, wo, active):
            nv = mi.Frame3f.cos_theta(wi)
            nl = mi.Frame3f.cos_theta(wo)
            active = active & (nv > 0) & (nl > 0)
            base = self.base.eval(si, active)
            f0 = dr.lerp(mi.Color3f(0.04), base, self.metallic)

            def schlick(u):
                m = 1.0 - dr.clip(u, 0.0, 1.0)
                m2 = m * m
                return f0 + (1.0 - f0) * (m2 * m2 * m)

            h = dr.normalize(wi + wo)
            d, _ = self._d(h)
            a2 = self._alpha() ** 2
            # (Clamped away from 0 only for the scalar variants' Python floats; inactive lanes.)
            nlc, nvc = dr.maximum(nl, 1e-7), dr.maximum(nv, 1e-7)
            vis = 0.5 / (nlc * dr.sqrt(nvc * nvc * (1.0 - a2) + a2) + nvc * dr.sqrt(nlc * nlc * (1.0 - a2) + a2))
            spec = schlick(dr.dot(wi, h)) * (d * vis)
            diff = (1.0 - self.metallic) * base * (1.0 - schlick(nv)) * (1.0 - schlick(nl)) / dr.pi
            return dr.select(active, diff + spec, 0.0), active

        def _pdf(self, wi, wo, active):
            nl = mi.Frame3f.cos_theta(wo)
            h = dr.normalize(wi + wo)
            d, nh = self._d(h)
            pdf_s = d * nh / (4.0 * dr.maximum(dr.abs(dr.dot(wi, h)), 1e-8))
            pdf = 0.5 * pdf_s + 0.5 * dr.maximum(nl, 0.0) / dr.pi
            return dr.select(active & (nl > 0), pdf, 0.0)

        def sample(self, ctx, si, sample1, sample2, active=True):
            wi = si.wi
            active = active & (mi.Frame3f.cos_theta(wi) > 0)
            a = self._alpha()
            a2 = a * a
            u1, u2 = sample2.x, sample2.y
            # GGX half-vector by inverting D's cdf in cos(theta_h).
            c = dr.sqrt(dr.maximum((1.0 - u1) / (1.0 + (a2 - 1.0) * u1), 0.0))
            st = dr.sqrt(dr.maximum(1.0 - c * c, 0.0))
            phi = 2.0 * dr.pi * u2
            h = mi.Vector3f(st * dr.cos(phi), st * dr.sin(phi), c)
            wo_s = 2.0 * dr.dot(wi, h) * h - wi
            wo_d = mi.warp.square_to_cosine_hemisphere(sample2)
            wo = dr.select(sample1 < 0.5, wo_s, wo_d)
            f, ok = self._f(si, wi, wo, active)
            pdf = self._pdf(wi, wo, ok)
            bs = mi.BSDFSample3f()
            bs.wo = wo
            bs.pdf = pdf
            bs.eta = 1.0
            bs.sampled_type = mi.UInt32(+mi.BSDFFlags.GlossyReflection)
            bs.sampled_component = 0
            w = dr.select(ok & (pdf > 0), f * mi.Frame3f.cos_theta(wo) / dr.maximum(pdf, 1e-20), 0.0)
            return bs, w

        def eval(self, ctx, si, wo, active=True):
            f, ok = self._f(si, si.wi, wo, active)
            return dr.select(ok, f * mi.Frame3f.cos_theta(wo), 0.0)

        def pdf(self, ctx, si, wo, active=True):
            return self._pdf(si.wi, wo, active & (mi.Frame3f.cos_theta(si.wi) > 0))

        def eval_pdf(self, ctx, si, wo, active=True):
            return self.eval(ctx, si, wo, active), self.pdf(ctx, si, wo, active)

        def eval_diffuse_reflectance(self, si, active=True):
            # The base colour: what the RSM's Lambert VPLs reflect (`lightcut_first_glossy`).
            return self.base.eval(si, active)

        def traverse(self, callback):
            callback.put_parameter("metallic", self.metallic, mi.ParamFlags.NonDifferentiable)

        def to_string(self):
            return f"LightcutGgx[metallic={self.metallic}, roughness={self.roughness}]"

    mi.register_bsdf("lightcut_ggx", lambda props: LightcutGgx(props))


def principled_probe(mi) -> list[dict]:
    """f x cos of Mitsuba's `principled` (as `--brdf principled` configures it) and of
    `lightcut_ggx` for one base colour, a few materials and directions (view 29 degrees, light
    11 .. 80 degrees in the plane of incidence, opposite side): where the two models agree."""
    import drjit as dr
    register_lightcut_ggx(mi)
    rows = []
    base = {"type": "rgb", "value": [0.8, 0.8, 0.8]}
    for metallic, rough in [(1.0, 0.17), (1.0, 0.5), (0.0, 0.39), (0.0, 0.97)]:
        p = mi.load_dict({"type": "principled", "base_color": base, "metallic": metallic, "roughness": rough,
                          "specular": 0.5, "spec_tint": 0.0, "anisotropic": 0.0, "sheen": 0.0, "clearcoat": 0.0,
                          "spec_trans": 0.0})
        g = mi.load_dict({"type": "lightcut_ggx", "base": base, "metallic": metallic, "roughness": rough})
        si = dr.zeros(mi.SurfaceInteraction3f)
        si.n = mi.Normal3f(0, 0, 1)
        si.sh_frame = mi.Frame3f(si.n)
        si.wi = mi.Vector3f(math.sin(0.5), 0, math.cos(0.5))
        for th in (0.2, 0.5, 1.0, 1.4):
            wo = mi.Vector3f(-math.sin(th), 0, math.cos(th))
            fp = float(np.array(p.eval(mi.BSDFContext(), si, wo)).ravel()[0])
            fg = float(np.array(g.eval(mi.BSDFContext(), si, wo)).ravel()[0])
            rows.append({"metallic": metallic, "roughness": rough, "light_deg": math.degrees(th),
                         "principled": fp, "ours": fg, "ratio": fp / fg if fg > 0 else None})
    return rows


def build_scene_dict(mi, scene_dir: Path, meta: dict, width: int, height: int, sampler: str, spp: int,
                     flip_v: bool, brdf: str = "lambert") -> dict:
    cam = meta["camera"]
    eye = np.asarray(cam["position"], dtype=float)
    fwd = np.asarray(cam["forward"], dtype=float)
    up = np.asarray(cam["up"], dtype=float)
    fwd = fwd / np.linalg.norm(fwd)
    d = {
        "type": "scene",
        "sensor": {
            "type": "perspective",
            "fov_axis": "y",
            "fov": float(cam["yfov_deg"]),
            "near_clip": 1e-3,
            "far_clip": 1e4,
            # Mitsuba cameras look down local +Z with +X image-left: build from look_at, never
            # from the glTF node matrix (see ../shared/docs/mitsuba-notes.md).
            "to_world": mi.ScalarTransform4f().look_at(origin=eye.tolist(), target=(eye + fwd).tolist(),
                                                        up=up.tolist()),
            "film": {
                "type": "hdrfilm",
                "width": width,
                "height": height,
                "pixel_format": "rgb",
                "component_format": "float32",
                "rfilter": {"type": "box"},
            },
            "sampler": {"type": sampler, "sample_count": spp},
        },
    }
    n_mesh = 0
    for i, m in enumerate(meta["materials"]):
        if not m.get("mesh"):
            continue
        albedo = [float(x) for x in m["albedo"]]
        if m.get("texture"):
            refl = {
                "type": "bitmap",
                "bitmap": load_texture(mi, scene_dir / m["texture"], albedo, flip_v),
                "raw": True,  # already linear
                "filter_type": "bilinear",
                "wrap_mode": "repeat",
            }
        else:
            refl = {"type": "rgb", "value": albedo}
        d[f"mesh_{i}"] = {
            "type": "ply",
            "filename": str(scene_dir / m["mesh"]),
            "face_normals": False,  # use the exported vertex normals as shading normals
            "bsdf": {"type": "twosided", "bsdf": (
                {"type": "diffuse", "reflectance": refl} if brdf == "lambert" else
                {"type": "principled", "base_color": refl, "metallic": float(m.get("metallic", 1.0)),
                 "roughness": float(m.get("roughness", 1.0)), "specular": 0.5, "spec_tint": 0.0,
                 "anisotropic": 0.0, "sheen": 0.0, "clearcoat": 0.0, "spec_trans": 0.0}
                if brdf == "principled" else
                {"type": "lightcut_ggx", "base": refl, "metallic": float(m.get("metallic", 1.0)),
                 "roughness": float(m.get("roughness", 1.0))})},
        }
        n_mesh += 1
    if n_mesh == 0:
        raise SystemExit("error: scene.json lists no meshes")
    for k, s in enumerate(meta.get("sun", [])):
        d[f"sun_{k}"] = {
            "type": "directional",
            "direction": [float(x) for x in s["direction"]],  # travel direction
            "irradiance": {"type": "rgb", "value": [float(x) for x in s["irradiance"]]},
        }
    if not meta.get("sun"):
        print("warning: scene.json has no sun; Mitsuba's image will be black", file=sys.stderr)
    return d


MAX_PASS_SPP = 64  # the JIT variants trace all of a pass's samples at once: bound the memory


def render(mi, scene, max_depth: int, spp: int, seed: int, integrator: dict | None = None) -> np.ndarray:
    """Average of ceil(spp / MAX_PASS_SPP) passes with seeds derived from `seed` (deterministic,
    so two calls with the same seed and spp use the same samples). `integrator`: instead of
    `path` with `max_depth`."""
    integ = mi.load_dict(integrator or {"type": "path", "max_depth": max_depth, "rr_depth": max_depth + 100,
                                        "hide_emitters": False})
    passes = max(1, -(-spp // MAX_PASS_SPP))
    per = spp // passes
    acc = None
    for k in range(passes):
        img = np.array(mi.render(scene, integrator=integ, spp=per, seed=seed * 1009 + k), dtype=np.float64)[:, :, :3]
        acc = img if acc is None else acc + img
    return acc / passes


def register_first_glossy(mi, bounces: int):
    """Registers `lightcut_first_glossy`: the indirect light as the workbench's VPLs carry it with
    `gi.brdf = ggx`. The camera's hit reflects with the scene's BSDF (`lightcut_ggx`), sampled by
    its own importance sampling; every later vertex is a Lambertian reflector of its base colour
    (the BSDF's `eval_diffuse_reflectance`), lit by the sun with a shadow ray, and continues by a
    cosine-weighted bounce: light paths are diffuse emitters, as the RSM's and the light paths'
    VPLs are. No emission at the camera's hit and no direct sun there: the indirect part of
    N = `bounces` diffuse bounces before the glossy receiver (Mitsuba's `path` would also carry
    glossy reflections of the sun into the scene, which no VPL does)."""
    import drjit as dr

    class FirstGlossy(mi.SamplingIntegrator):
        def __init__(self, props):
            mi.SamplingIntegrator.__init__(self, props)

        def sample(self, scene, sampler, ray, medium=None, active=True):
            ctx = mi.BSDFContext()
            si = scene.ray_intersect(ray, active)
            valid = si.is_valid()
            act = mi.Bool(active) & valid
            bsdf = si.bsdf(ray)
            bs, w = bsdf.sample(ctx, si, sampler.next_1d(act), sampler.next_2d(act), act)
            act &= (bs.pdf > 0) & dr.any(w > 0)
            throughput = mi.Spectrum(w)
            ray = si.spawn_ray(si.to_world(bs.wo))
            result = mi.Spectrum(0.0)
            for depth in range(bounces):
                si = scene.ray_intersect(ray, act)
                act &= si.is_valid()
                albedo = si.bsdf(ray).eval_diffuse_reflectance(si, act)
                n = si.sh_frame.n
                n = dr.select(dr.dot(n, -ray.d) < 0, -n, n)  # two-sided: the side the ray arrives at
                ds, em = scene.sample_emitter_direction(si, sampler.next_2d(act), True, act)
                cos = dr.maximum(dr.dot(n, ds.d), 0.0)
                result += dr.select(act, throughput * albedo / dr.pi * em * cos, 0.0)
                if depth + 1 < bounces:
                    wo = mi.Frame3f(n).to_world(mi.warp.square_to_cosine_hemisphere(sampler.next_2d(act)))
                    throughput *= albedo
                    ray = si.spawn_ray(wo)
            return result, valid, []

    mi.register_integrator("lightcut_first_glossy", lambda props: FirstGlossy(props))


def render_first_glossy(mi, scene, spp: int, seed: int) -> np.ndarray:
    """`render` with `lightcut_first_glossy` (registered by `register_first_glossy`)."""
    return render(mi, scene, 0, spp, seed, {"type": "lightcut_first_glossy"})


# ----------------------------------------------------------------------------------------------
# Comparison


def read_exr_rgb(mi, path: Path) -> np.ndarray:
    bmp = mi.Bitmap(str(path))
    arr = np.array(bmp, dtype=np.float64)
    if arr.ndim == 2:
        arr = np.repeat(arr[:, :, None], 3, axis=2)
    return arr[:, :, :3]


def region_means(img: np.ndarray, n: int) -> np.ndarray:
    """Mean (over pixels and RGB) of each of n x n blocks: shape (n, n)."""
    h, w = img.shape[:2]
    ys = np.linspace(0, h, n + 1).round().astype(int)
    xs = np.linspace(0, w, n + 1).round().astype(int)
    out = np.zeros((n, n))
    for a in range(n):
        for b in range(n):
            out[a, b] = img[ys[a]:ys[a + 1], xs[b]:xs[b + 1]].mean()
    return out


def rel(a, b):
    b = np.asarray(b, dtype=np.float64)
    return np.where(np.abs(b) > 0, (np.asarray(a) - b) / np.where(np.abs(b) > 0, b, 1.0), np.nan)


def compare(ours: np.ndarray, mts_splits: list[np.ndarray], grid: int, albedo: np.ndarray | None = None,
            mat_id: np.ndarray | None = None, mat_names: list[str] | None = None) -> dict:
    k = len(mts_splits)
    mts = np.mean(mts_splits, axis=0)
    diff = ours - mts
    mean_o = ours.reshape(-1, 3).mean(axis=0)
    mean_m = mts.reshape(-1, 3).mean(axis=0)
    split_means = np.array([s.reshape(-1, 3).mean(axis=0) for s in mts_splits])  # (k, 3)
    se_chan = split_means.std(axis=0, ddof=1) / math.sqrt(k) if k > 1 else np.full(3, np.nan)
    split_overall = split_means.mean(axis=1)
    se_overall = split_overall.std(ddof=1) / math.sqrt(k) if k > 1 else float("nan")
    rmse = float(np.sqrt(np.mean(diff ** 2)))
    # Mitsuba's own per-pixel noise (standard error of the averaged image), from the splits.
    if k > 1:
        pix_var = np.var(np.stack(mts_splits), axis=0, ddof=1) / k
        mts_noise_rms = float(np.sqrt(pix_var.mean()))
    else:
        mts_noise_rms = float("nan")
    # RMSE with Mitsuba's noise removed in expectation: E[diff^2] = bias^2 + noise var.
    rmse_debiased = float(np.sqrt(max(rmse ** 2 - mts_noise_rms ** 2, 0.0))) if k > 1 else float("nan")

    reg_o = region_means(ours, grid)
    reg_m = region_means(mts, grid)
    reg_splits = np.array([region_means(s, grid) for s in mts_splits])
    reg_se = reg_splits.std(axis=0, ddof=1) / math.sqrt(k) if k > 1 else np.full((grid, grid), np.nan)
    reg_rel = rel(reg_o, reg_m)

    # Pixel-level error distribution (relative to the Mitsuba mean, so dark pixels do not dominate).
    lum_o = ours.mean(axis=2)
    lum_m = mts.mean(axis=2)
    ad = np.abs(lum_o - lum_m)
    scale = max(float(lum_m.mean()), 1e-30)
    frac_big = float(np.mean(ad > 0.25 * scale))
    # Share of the absolute error carried by the worst 5% of the lit pixels (non-zero in either).
    lit_any = (lum_o != 0) | (lum_m != 0)
    srt = np.sort(ad[lit_any])[::-1] if lit_any.any() else np.zeros(1)
    top = max(1, int(0.05 * srt.size))
    top_share = float(srt[:top].sum() / max(srt.sum(), 1e-30))

    # Smooth-interior vs edge pixels, from our (noise-free) image divided by our albedo buffer
    # when given (so texture edges do not count): a pixel is "edge" when the range of its 3x3
    # neighbourhood exceeds 25% of that neighbourhood's maximum (shadow boundaries,
    # silhouettes). Interior pixels test irradiance, cosine, albedo and texture decoding; edge
    # pixels also test shadow-map and rasterisation effects.
    h, w = lum_o.shape
    shade = lum_o
    if albedo is not None:
        al = albedo.mean(axis=2)
        shade = np.where(al > 1e-6, lum_o / np.maximum(al, 1e-6), 0.0)
    pad = np.pad(shade, 1, mode="edge")
    win = np.stack([pad[dy:dy + h, dx:dx + w] for dy in range(3) for dx in range(3)])
    lo_, hi_ = win.min(axis=0), win.max(axis=0)
    edge = (hi_ - lo_) > 0.25 * np.maximum(hi_, 1e-30)
    lit = lum_o + lum_m > 0
    interior = lit & ~edge
    edge_lit = lit & edge

    def masked(mask):
        if not mask.any():
            return {"pixels": 0}
        so, sm = float(lum_o[mask].sum()), float(lum_m[mask].sum())
        return {
            "pixels": int(mask.sum()),
            "fraction_of_image": float(mask.mean()),
            "sum_ours": so,
            "sum_mitsuba": sm,
            "rel_err": (so - sm) / sm if sm > 0 else None,
            "share_of_mitsuba_total": sm / max(float(lum_m.sum()), 1e-30),
        }

    # Region errors: only blocks holding at least 10% of the image mean are ranked.
    sig = reg_m > 0.1 * max(float(mean_m.mean()), 1e-30)
    reg_max = float(np.nanmax(np.abs(reg_rel[sig]))) if sig.any() else None

    # Per material, from our G-buffer's material id (pixels where our rasteriser saw material m;
    # Mitsuba's value at the same pixels, so silhouettes mix in a little of the neighbours).
    per_mat = []
    if mat_id is not None:
        for m in range(int(mat_id.max()) + 1 if mat_id.size else 0):
            mask = mat_id == m
            if not mask.any():
                continue
            so = ours[mask].sum(axis=0)
            sm = mts[mask].sum(axis=0)
            per_mat.append({
                "material": m,
                "name": mat_names[m] if mat_names and m < len(mat_names) else str(m),
                "pixels": int(mask.sum()),
                "share_of_mitsuba_total": float(sm.sum() / max(float(mts.sum()), 1e-30)),
                "rel_err_rgb": [float((so[c] - sm[c]) / sm[c]) if sm[c] > 0 else None for c in range(3)],
                "rel_err": float((so.sum() - sm.sum()) / sm.sum()) if sm.sum() > 0 else None,
                "abs_err_share_of_image_mean_err": float((so.sum() - sm.sum()) / (ours.sum() - mts.sum()))
                if ours.sum() != mts.sum() else None,
            })

    return {
        "per_material": per_mat,
        "interior_pixels": masked(interior),
        "edge_pixels": masked(edge_lit),
        "mean_ours_rgb": mean_o.tolist(),
        "mean_mitsuba_rgb": mean_m.tolist(),
        "mean_rel_err_rgb": rel(mean_o, mean_m).tolist(),
        "mean_ours": float(mean_o.mean()),
        "mean_mitsuba": float(mean_m.mean()),
        "mean_rel_err": float(rel(mean_o.mean(), mean_m.mean())),
        "mitsuba_mean_stderr_rgb": np.asarray(se_chan).tolist(),
        "mitsuba_mean_rel_stderr": float(se_overall / mean_m.mean()) if mean_m.mean() > 0 else float("nan"),
        "rmse": rmse,
        "rmse_rel_to_mean": rmse / scale,
        "mitsuba_pixel_noise_rms": mts_noise_rms,
        "rmse_without_mitsuba_noise": rmse_debiased,
        "pixels_off_by_more_than_25pct_of_mean": frac_big,
        "abs_error_share_of_worst_5pct_lit_pixels": top_share,
        "grid": grid,
        "region_mean_ours": reg_o.tolist(),
        "region_mean_mitsuba": reg_m.tolist(),
        "region_mitsuba_stderr": np.asarray(reg_se).tolist(),
        "region_rel_err": np.where(np.isnan(reg_rel), None, reg_rel).tolist(),
        "region_max_abs_rel_err": reg_max,
        "region_significant": sig.tolist(),
    }


# ----------------------------------------------------------------------------------------------
# Images


def tonemap(img: np.ndarray, scale: float) -> np.ndarray:
    x = np.clip(img * scale, 0, None)
    x = x / (1.0 + x)  # Reinhard, then sRGB OETF
    s = np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)
    return np.clip(s * 255 + 0.5, 0, 255).astype(np.uint8)


def diff_colour(ours: np.ndarray, mts: np.ndarray, limit: float = 0.5) -> np.ndarray:
    """Relative difference (ours - Mitsuba) / Mitsuba-mean-scale: blue = ours darker, red = brighter,
    white = equal; saturates at +-limit. Normalised by max(pixel, 10% of the image mean)."""
    lo, lm = ours.mean(axis=2), mts.mean(axis=2)
    denom = np.maximum(lm, 0.1 * max(float(lm.mean()), 1e-30))
    r = np.clip((lo - lm) / denom / limit, -1, 1)
    out = np.ones(r.shape + (3,))
    pos, neg = np.clip(r, 0, 1), np.clip(-r, 0, 1)
    out[:, :, 1] -= pos + neg
    out[:, :, 2] -= pos
    out[:, :, 0] -= neg
    return np.clip(np.clip(out, 0, 1) * 255 + 0.5, 0, 255).astype(np.uint8)


def write_png(mi, path: Path, rgb8: np.ndarray):
    mi.Bitmap(np.ascontiguousarray(rgb8), mi.Bitmap.PixelFormat.RGB).write(str(path))


def write_exr(mi, path: Path, rgb: np.ndarray):
    mi.Bitmap(np.ascontiguousarray(rgb.astype(np.float32)), mi.Bitmap.PixelFormat.RGB).write(str(path))


# ----------------------------------------------------------------------------------------------
# Report


def fmt_pct(x):
    return "n/a" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{100 * x:+.2f}%"


def part_md(name: str, r: dict) -> str:
    g = r["grid"]
    lines = [
        f"### {name}",
        "",
        "| | R | G | B | all |",
        "|---|---|---|---|---|",
        "| ours mean | " + " | ".join(f"{v:.5f}" for v in r["mean_ours_rgb"]) + f" | {r['mean_ours']:.5f} |",
        "| Mitsuba mean | " + " | ".join(f"{v:.5f}" for v in r["mean_mitsuba_rgb"]) + f" | {r['mean_mitsuba']:.5f} |",
        "| relative error | " + " | ".join(fmt_pct(v) for v in r["mean_rel_err_rgb"]) + f" | {fmt_pct(r['mean_rel_err'])} |",
        "| Mitsuba std. error of mean | " + " | ".join(f"{v:.2e}" for v in r["mitsuba_mean_stderr_rgb"])
        + f" | {100 * r['mitsuba_mean_rel_stderr']:.3f}% (relative) |",
        "",
        f"- RMSE (per pixel and channel): {r['rmse']:.5f} = {100 * r['rmse_rel_to_mean']:.1f}% of the Mitsuba mean; "
        f"Mitsuba's own pixel noise (RMS std. error): {r['mitsuba_pixel_noise_rms']:.5f}; "
        f"RMSE with that noise removed: {r['rmse_without_mitsuba_noise']:.5f}",
        f"- pixels whose |difference| exceeds 25% of the image mean: {100 * r['pixels_off_by_more_than_25pct_of_mean']:.2f}%; "
        f"the worst 5% of the lit pixels carry {100 * r['abs_error_share_of_worst_5pct_lit_pixels']:.0f}% of the absolute error",
        "",
        f"Region means ({g}x{g} blocks, row 0 = top; ours / Mitsuba / relative error):",
        "",
        "| row | " + " | ".join(f"col {b}" for b in range(g)) + " |",
        "|---|" + "---|" * g,
    ]
    for a in range(g):
        cells = []
        for b in range(g):
            re_ = r["region_rel_err"][a][b]
            cells.append(f"{r['region_mean_ours'][a][b]:.4f} / {r['region_mean_mitsuba'][a][b]:.4f} / {fmt_pct(re_)}")
        lines.append(f"| {a} | " + " | ".join(cells) + " |")
    lines.append("")
    lines.append(f"Largest region |relative error| (blocks with at least 10% of the image mean): "
                 f"{fmt_pct(r['region_max_abs_rel_err'])}")
    lines.append("")
    if r.get("per_material"):
        lines += ["Per material (pixels where our G-buffer sees it):", "",
                  "| material | pixels | share of Mitsuba total | rel. error R | G | B | all | share of the image-mean error |",
                  "|---|---|---|---|---|---|---|---|"]
        for m in r["per_material"]:
            sh = m["abs_err_share_of_image_mean_err"]
            lines.append(f"| {m['name']} | {m['pixels']} | {100 * m['share_of_mitsuba_total']:.1f}% | "
                         + " | ".join(fmt_pct(v) for v in m["rel_err_rgb"])
                         + f" | {fmt_pct(m['rel_err'])} | {'n/a' if sh is None else f'{100 * sh:.0f}%'} |")
        lines.append("")
    for key, label in (("interior_pixels", "smooth interior"), ("edge_pixels", "edge")):
        m = r[key]
        if m.get("pixels"):
            lines.append(f"- {label} pixels (lit, {100 * m['fraction_of_image']:.1f}% of the image, "
                         f"{100 * m['share_of_mitsuba_total']:.0f}% of Mitsuba's energy): "
                         f"sum relative error {fmt_pct(m['rel_err'])}")
    lines.append("")
    return "\n".join(lines)


def main(argv=None) -> int:
    a = parse_args(argv)
    meta_path = a.scene_dir / "scene.json"
    try:
        meta = json.loads(meta_path.read_text())
    except (OSError, json.JSONDecodeError) as e:
        raise SystemExit(f"error: cannot read {meta_path}: {e}")
    ours_direct_path = a.ours / "direct.exr"
    ours_ind_path = a.ours / "indirect.exr"
    if not ours_direct_path.exists():
        raise SystemExit(f"error: {ours_direct_path} not found (run `lightcut-workbench render --out {a.ours}`)")
    if a.bounces < 1:
        raise SystemExit("error: --bounces must be at least 1")
    if a.indirect and not ours_ind_path.exists():
        raise SystemExit(f"error: --indirect given but {ours_ind_path} does not exist (indirect not rendered yet)")
    if a.brdf == "principled" and a.indirect:
        raise SystemExit("error: --brdf principled compares the direct light only (drop --indirect)")
    if a.splits < 1 or a.spp < a.splits:
        raise SystemExit("error: need --splits >= 1 and --spp >= --splits")

    if a.variant.startswith("llvm") and "DRJIT_LIBLLVM_PATH" not in os.environ:
        # Debian 12's LLVM 15 crashes Dr.Jit ("Cannot select fminimum"); `apt-get install libllvm19`.
        for cand in ("/usr/lib/x86_64-linux-gnu/libLLVM-19.so.1", "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1",
                     "/usr/lib/x86_64-linux-gnu/libLLVM-19.so"):
            if os.path.exists(cand):
                os.environ["DRJIT_LIBLLVM_PATH"] = cand
                break
    import mitsuba as mi

    try:
        mi.set_variant(a.variant)
    except Exception as e:  # noqa: BLE001 - mitsuba raises plain exceptions
        raise SystemExit(f"error: Mitsuba variant {a.variant!r} unavailable: {e}")

    # Ours may be rendered at k x the size (k integer): it is then box-filtered down, which is
    # what Mitsuba's box pixel filter does, so pixel-centre aliasing drops out of the comparison.
    def load_ours(path: Path, what: str):
        img = read_exr_rgb(mi, path) if what != "position" else np.array(mi.Bitmap(str(path)), dtype=np.float64)
        h, w = img.shape[:2]
        k = h // a.height
        if k < 1 or h != k * a.height or w != k * a.width:
            raise SystemExit(f"error: {path} is {w}x{h}, but --width/--height say {a.width}x{a.height} "
                             "(or an integer multiple)")
        if k == 1:
            return img, 1
        if what == "position":  # material ids cannot be averaged: take the sample nearest the centre
            return img[k // 2::k, k // 2::k], k
        return img.reshape(a.height, k, a.width, k, img.shape[2]).mean(axis=(1, 3)), k

    ours_direct, ours_ss = load_ours(ours_direct_path, "direct")
    a.out.mkdir(parents=True, exist_ok=True)
    ours_albedo = None
    if (a.ours / "albedo.exr").exists():
        ours_albedo, _ = load_ours(a.ours / "albedo.exr", "albedo")
    mat_id, mat_names = None, [m.get("name", str(i)) for i, m in enumerate(meta["materials"])]
    if (a.ours / "position.exr").exists():
        pos, _ = load_ours(a.ours / "position.exr", "position")
        if pos.ndim == 3 and pos.shape[2] >= 4:
            mat_id = np.rint(pos[:, :, 3]).astype(np.int64) - 1  # w = material id + 1, 0 = none

    def spp_split(total):
        per = max(1, total // a.splits)
        if a.sampler == "ldsampler" and per & (per - 1):
            per = 1 << (per.bit_length() - 1)  # ldsampler wants a power of two
        return per

    t0 = time.time()
    per = spp_split(a.spp)
    if a.brdf == "ggx":
        register_lightcut_ggx(mi)
        register_first_glossy(mi, a.bounces)
    scene = mi.load_dict(build_scene_dict(mi, a.scene_dir, meta, a.width, a.height, a.sampler, per, a.flip_v,
                                          a.brdf))
    t_load = time.time() - t0
    if a.self_check:
        if a.brdf != "lambert" or a.bounces != 1:
            raise SystemExit("error: --self-check compares with `path` and needs --brdf lambert --bounces 1")
        register_first_glossy(mi, 1)
        fg = [render_first_glossy(mi, scene, per, a.seed + 1000 * s) for s in range(a.splits)]
        pd = [render(mi, scene, 3, per, a.seed + 1000 * s) - render(mi, scene, 2, per, a.seed + 1000 * s)
              for s in range(a.splits)]
        m_fg, m_pd = float(np.mean(fg)), float(np.mean(pd))
        se = float(np.std([f.mean() - p.mean() for f, p in zip(fg, pd)]) / max(math.sqrt(a.splits), 1.0))
        print(f"self-check: lightcut_first_glossy {m_fg:.6f}, path(3) - path(2) {m_pd:.6f}: "
              f"{(m_fg / m_pd - 1) * 100:+.2f}% (difference's std. error {se / m_pd * 100:.2f}%)")
        return 0

    if a.brdf == "principled":
        probe = principled_probe(mi)
        print("principled / ours (f x cos, view 29 deg):")
        for r in probe:
            print(f"  metallic {r['metallic']:.0f} roughness {r['roughness']:.2f} light {r['light_deg']:5.1f} deg: "
                  f"{r['principled']:.5g} / {r['ours']:.5g} = {r['ratio']:.4f}")
    report = {
        "mitsuba_version": mi.__version__,
        "variant": a.variant,
        "sampler": a.sampler,
        "splits": a.splits,
        "scene_dir": str(a.scene_dir),
        "ours": str(a.ours),
        "width": a.width,
        "height": a.height,
        "camera": meta["camera"],
        "sun": meta.get("sun", []),
        "flip_v": a.flip_v,
        "brdf": a.brdf,
        "seed": a.seed,
        "ours_supersampling": ours_ss,
        "scene_load_s": t_load,
        "parts": {},
    }

    def cached(part: str, spp_total: int):
        """Split images of `part` from --reuse-mitsuba, or None when absent or made differently."""
        if a.reuse_mitsuba is None:
            return None
        try:
            old = json.loads((a.reuse_mitsuba / "report.json").read_text())
        except (OSError, json.JSONDecodeError):
            return None
        same = (old.get("variant") == a.variant and old.get("sampler") == a.sampler
                and old.get("splits") == a.splits and old.get("seed") == a.seed
                and old.get("width") == a.width and old.get("height") == a.height
                and old.get("camera") == meta["camera"] and old.get("sun") == meta.get("sun", [])
                and old.get("flip_v") == a.flip_v and old.get("brdf", "lambert") == a.brdf
                and old.get("parts", {}).get(part, {}).get("spp") == spp_total)
        files = [a.reuse_mitsuba / f"mitsuba_{part}_split{k}.exr" for k in range(a.splits)]
        if not same or not all(f.exists() for f in files):
            print(f"note: --reuse-mitsuba {a.reuse_mitsuba} does not match for {part}; rendering", file=sys.stderr)
            return None
        old_part = old["parts"][part]
        return [read_exr_rgb(mi, f) for f in files], old_part.get("render_s", 0.0)

    def save_splits(part: str, splits):
        for k, img in enumerate(splits):
            write_exr(mi, a.out / f"mitsuba_{part}_split{k}.exr", img)

    # Direct: path max_depth = 2.
    t0 = time.time()
    hit = cached("direct", per * a.splits)
    reused_direct = bool(hit)
    if hit:
        d_splits, t_direct = hit
        report["reused_mitsuba_from"] = str(a.reuse_mitsuba)
    else:
        d_splits = [render(mi, scene, 2, per, a.seed + 1000 * s) for s in range(a.splits)]
        t_direct = time.time() - t0
    save_splits("direct", d_splits)
    mts_direct = np.mean(d_splits, axis=0)
    write_exr(mi, a.out / "mitsuba_direct.exr", mts_direct)
    r = compare(ours_direct, d_splits, a.grid, ours_albedo, mat_id, mat_names)
    r.update({"spp": per * a.splits, "render_s": t_direct, "max_depth": 2, "reused": reused_direct})
    report["parts"]["direct"] = r
    scale = 1.0 / max(float(np.percentile(mts_direct, 99.5)), 1e-30)
    strip = np.concatenate([tonemap(ours_direct, scale), tonemap(mts_direct, scale),
                            diff_colour(ours_direct, mts_direct)], axis=1)
    write_png(mi, a.out / "compare_direct.png", strip)

    if a.indirect:
        ours_ind, _ = load_ours(ours_ind_path, "indirect")
        per_i = spp_split(a.indirect_spp or a.spp)
        scene_i = scene
        if per_i != per:
            scene_i = mi.load_dict(build_scene_dict(mi, a.scene_dir, meta, a.width, a.height, a.sampler, per_i,
                                                    a.flip_v, a.brdf))
        t0 = time.time()
        # One bounce keeps the part's old name (and its cached images); N bounces: indirectN.
        part = "indirect" if a.bounces == 1 else f"indirect{a.bounces}"
        hit = cached(part, per_i * a.splits)
        reused_ind = bool(hit)
        if hit:
            i_splits, t_ind = hit
        else:
            i_splits = []
            for s in range(a.splits):
                seed = a.seed + 7919 + 1000 * s
                if a.brdf == "ggx":
                    # GGX at the camera's hit, diffuse emitters beyond (as our VPLs).
                    i_splits.append(render_first_glossy(mi, scene_i, per_i, seed))
                    continue
                # Same seed for both depths so the direct part cancels in the difference.
                i_splits.append(render(mi, scene_i, a.bounces + 2, per_i, seed) - render(mi, scene_i, 2, per_i, seed))
            t_ind = time.time() - t0
        save_splits(part, i_splits)
        mts_ind = np.mean(i_splits, axis=0)
        write_exr(mi, a.out / f"mitsuba_{part}.exr", mts_ind)
        r = compare(ours_ind, i_splits, a.grid, ours_albedo, mat_id, mat_names)
        how = "lightcut_first_glossy" if a.brdf == "ggx" else f"{a.bounces + 2} minus 2"
        r.update({"spp": per_i * a.splits, "render_s": t_ind, "max_depth": how, "bounces": a.bounces, "reused": reused_ind})
        report["parts"][part] = r
        scale = 1.0 / max(float(np.percentile(mts_ind, 99.5)), 1e-30)
        strip = np.concatenate([tonemap(ours_ind, scale), tonemap(mts_ind, scale),
                                diff_colour(ours_ind, mts_ind)], axis=1)
        write_png(mi, a.out / f"compare_{part}.png", strip)

    def clean(o):
        if isinstance(o, float) and not math.isfinite(o):
            return None
        if isinstance(o, dict):
            return {k: clean(v) for k, v in o.items()}
        if isinstance(o, list):
            return [clean(v) for v in o]
        return o

    (a.out / "report.json").write_text(json.dumps(clean(report), indent=2) + "\n")

    md = [
        "# Mitsuba 3 check",
        "",
        f"- scene: `{a.scene_dir}` (camera '{meta['camera'].get('name', '?')}'), ours: `{a.ours}`, {a.width}x{a.height}"
        + (f" (ours rendered at {ours_ss}x and box-filtered down)" if ours_ss > 1 else " (ours: one sample at each pixel centre)"),
        f"- Mitsuba {mi.__version__}, variant `{a.variant}`, sampler `{a.sampler}`, {a.splits} independent splits, "
        "box pixel filter, `path` integrator (rr_depth > max_depth), two-sided diffuse",
        f"- images: `compare_<part>.png` = ours | Mitsuba | (ours - Mitsuba) / Mitsuba "
        "(blue: ours darker, red: ours brighter, saturating at 50%)",
        "",
    ]
    for name, r in report["parts"].items():
        md.append(f"_{name}: {r['spp']} spp, {r['render_s']:.1f} s{' (Mitsuba images reused from ' + str(a.reuse_mitsuba) + ')' if r.get('reused') else ''}_")
        md.append("")
        md.append(part_md(name, r))
    if not a.indirect:
        md.append("Indirect: not compared (run with `--indirect` once `indirect.exr` exists).")
        md.append("")
    (a.out / "report.md").write_text("\n".join(md))

    for name, r in report["parts"].items():
        print(f"{name}: ours {r['mean_ours']:.5f}  Mitsuba {r['mean_mitsuba']:.5f}  "
              f"rel.err {fmt_pct(r['mean_rel_err'])} (R {fmt_pct(r['mean_rel_err_rgb'][0])}, "
              f"G {fmt_pct(r['mean_rel_err_rgb'][1])}, B {fmt_pct(r['mean_rel_err_rgb'][2])}); "
              f"Mitsuba std.err {100 * r['mitsuba_mean_rel_stderr']:.3f}%; RMSE {r['rmse']:.5f} "
              f"({100 * r['rmse_rel_to_mean']:.1f}% of mean); worst region {fmt_pct(r['region_max_abs_rel_err'])}; "
              f"interior {fmt_pct(r['interior_pixels'].get('rel_err'))}, edges {fmt_pct(r['edge_pixels'].get('rel_err'))}; "
              f"{r['spp']} spp in {r['render_s']:.1f} s ({a.variant}{', reused' if r.get('reused') else ''})")
    print(f"wrote {a.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
