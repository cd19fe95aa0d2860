//! One view pane: its image (fitted, zoomed, panned), the pointer's pixel, clicks and the A/B
//! rectangle, and what is drawn over the image (the trees' divider, the A/B metrics, the
//! pinned pixel, the method's world-space overlay, the truth's progress, the legend).

use super::toolbar::{draw_legend, view_toolbar};
use super::*;

pub(super) fn view_pane_ui(cx: &mut PaneContext<'_>, ui: &mut egui::Ui, pane: &mut ViewPane) -> UiResponse {
    let response = view_toolbar(cx, ui, pane);
    // The image takes the rest of the pane (never wider than the pane).
    let pane_rect = ui.max_rect();
    let top = ui.cursor().top();
    let avail =
        egui::vec2(pane_rect.width(), (pane_rect.bottom() - top).max(16.0)).max(egui::vec2(16.0, 16.0));
    let (rect, resp) = ui.allocate_exact_size(avail, egui::Sense::click_and_drag());
    let ppp = ui.ctx().pixels_per_point();
    pane.rt.size_px = Some(rect.size() * ppp);
    ui.painter().rect_filled(rect, 0.0, egui::Color32::from_gray(12));
    let Some(slot) = pane.rt.slot else {
        return response;
    };
    let Some((tex, view, generation)) = cx.renderer.view_texture_at(slot) else {
        return response;
    };
    let (tw, th) = (tex.width().max(1), tex.height().max(1));
    let t = *cx.transform;
    let filter = if t.zoom > 1.01 || !cx.linear_filter {
        wgpu::FilterMode::Nearest
    } else {
        wgpu::FilterMode::Linear
    };
    let id = pane.rt.texture.update(cx.render_state, view, generation, filter);
    let aspect = tw as f32 / th as f32;
    let fit = if rect.width() / rect.height() > aspect {
        egui::vec2(rect.height() * aspect, rect.height())
    } else {
        egui::vec2(rect.width(), rect.width() / aspect)
    };
    let size = fit * t.zoom;
    let disp = egui::Rect::from_min_size(
        rect.center() - egui::vec2(t.center[0] * size.x, t.center[1] * size.y),
        size,
    );
    let painter = ui.painter_at(rect);
    let at = Placed {
        rect,
        disp,
        fit,
        size,
        tw,
        th,
        ppp,
    };
    painter.image(
        id,
        disp,
        egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0)),
        egui::Color32::WHITE,
    );
    draw_tree_divider(cx, &painter, &at, pane);
    let (fw, fh) = cx.renderer.size();
    let buffer = pane.spec.buffer;
    let ab = pane.spec.effective_ab();
    let side_by_side = ab.is_some_and(|a| a.mode == AbMode::SideBySide);
    zoom_and_pan(cx, ui, &resp, &at, ab.is_some());
    pointer_events(cx, ui, &resp, &at, pane);
    draw_ab(&painter, &at, pane, (fw, fh));
    draw_pinned(cx, &painter, &at, buffer, side_by_side);
    if !cx.overlay.is_empty() && !buffer.is_rsm_space() && !side_by_side {
        draw_overlay(cx, &painter, &at);
    }
    if (t.zoom - 1.0).abs() > 1e-3 {
        painter.text(
            rect.right_top() + egui::vec2(-6.0, 4.0),
            egui::Align2::RIGHT_TOP,
            format!("{:.0}% · F fits", 100.0 * disp.width() / (tw as f32 / ppp)),
            egui::FontId::proportional(11.0),
            egui::Color32::from_gray(220),
        );
    }
    draw_truth_progress(cx, &painter, rect, pane);
    draw_legend(cx, &painter, rect, pane);
    response
}

/// Where a pane's image lies: the pane's image area, the image's displayed rectangle, its
/// size fitted to the area (zoom 1) and zoomed, the texture's size, points per pixel.
#[derive(Clone, Copy)]
struct Placed {
    rect: egui::Rect,
    disp: egui::Rect,
    fit: egui::Vec2,
    size: egui::Vec2,
    tw: u32,
    th: u32,
    ppp: f32,
}

/// The tree overlay's two trees side by side: the divider and which half is which.
fn draw_tree_divider(cx: &PaneContext<'_>, painter: &egui::Painter, at: &Placed, pane: &ViewPane) {
    let (rect, disp) = (at.rect, at.disp);
    let d = cx.display;
    if d.tree_compare
        && d.tree_overlay != crate::settings::TreeOverlay::Off
        && !pane.spec.buffer.is_rsm_space()
        && pane.spec.effective_ab().is_none()
    {
        let x = disp.center().x;
        painter.line_segment(
            [egui::pos2(x, disp.top()), egui::pos2(x, disp.bottom())],
            egui::Stroke::new(1.5, egui::Color32::from_white_alpha(200)),
        );
        let font = egui::FontId::proportional(14.0);
        for (dx, align, text) in [
            (-8.0, egui::Align2::RIGHT_TOP, "perfect binary tree"),
            (8.0, egui::Align2::LEFT_TOP, "radix tree (LBVH)"),
        ] {
            let at = egui::pos2(x + dx, disp.top().max(rect.top()) + 6.0);
            painter.text(
                at + egui::vec2(1.0, 1.0),
                align,
                text,
                font.clone(),
                egui::Color32::BLACK,
            );
            painter.text(at, align, text, font.clone(), egui::Color32::WHITE);
        }
    }
}

/// Shared zoom (ctrl + wheel or pinch, about the pointer) and pan (ctrl/middle drag); a
/// plain drag turns the camera (not while shift selects an A/B rectangle).
fn zoom_and_pan(cx: &mut PaneContext<'_>, ui: &egui::Ui, resp: &egui::Response, at: &Placed, ab: bool) {
    let (rect, disp, fit, size) = (at.rect, at.disp, at.fit, at.size);
    let (tw, ppp) = (at.tw, at.ppp);
    let t = *cx.transform;
    if resp.hovered() {
        cx.events.hovered = true;
        let zoom = ui.input(|i| i.zoom_delta());
        if zoom != 1.0
            && let Some(pos) = resp.hover_pos()
        {
            let uv = (pos - disp.min) / disp.size();
            let z = (t.zoom * zoom).clamp(0.25, 512.0);
            let off = (pos - rect.center()) / (fit * z);
            cx.transform.zoom = z;
            cx.transform.center = [uv.x - off.x, uv.y - off.y];
        } else {
            cx.events.scroll += ui.input(|i| i.smooth_scroll_delta.y);
        }
        ui.input(|i| {
            if i.key_pressed(egui::Key::F) {
                *cx.transform = ViewTransform::default();
            }
            if i.key_pressed(egui::Key::Num1) {
                // One texel per physical pixel.
                cx.transform.zoom = tw as f32 / (fit.x * ppp);
            }
        });
    }
    let shift = ui.input(|i| i.modifiers.shift);
    let selecting = ab && shift && resp.dragged_by(egui::PointerButton::Primary);
    if resp.dragged() && !selecting {
        let d = resp.drag_delta();
        let pan = ui.input(|i| i.modifiers.command || i.modifiers.ctrl)
            || resp.dragged_by(egui::PointerButton::Middle);
        if pan {
            cx.transform.center[0] -= d.x / size.x;
            cx.transform.center[1] -= d.y / size.y;
        } else {
            let primary = resp.dragged_by(egui::PointerButton::Primary);
            cx.events.camera_drag = Some((Vec2::new(d.x, d.y), primary));
        }
    }
}

/// The frame pixel under the pointer (camera-space views), a click, and shift + drag on an
/// A/B view: the rectangle the metrics also measure.
fn pointer_events(
    cx: &mut PaneContext<'_>,
    ui: &egui::Ui,
    resp: &egui::Response,
    at: &Placed,
    pane: &mut ViewPane,
) {
    let (disp, tw, th) = (at.disp, at.tw, at.th);
    let (fw, fh) = cx.renderer.size();
    let buffer = pane.spec.buffer;
    let ab = pane.spec.effective_ab();
    let side_by_side = ab.is_some_and(|a| a.mode == AbMode::SideBySide);
    let shift = ui.input(|i| i.modifiers.shift);
    let selecting = ab.is_some() && shift && resp.dragged_by(egui::PointerButton::Primary);
    type Hit = Option<((u32, u32), Option<(u32, u32)>)>;
    let to_pixel = |pos: egui::Pos2| -> Hit {
        if !disp.contains(pos) {
            return None;
        }
        let uv = (pos - disp.min) / disp.size();
        let texel = (
            ((uv.x * tw as f32) as u32).min(tw - 1),
            ((uv.y * th as f32) as u32).min(th - 1),
        );
        let pixel = (!buffer.is_rsm_space()).then(|| {
            let u = if side_by_side { (uv.x * 2.0).fract() } else { uv.x };
            (
                ((u * fw as f32) as u32).min(fw - 1),
                ((uv.y * fh as f32) as u32).min(fh - 1),
            )
        });
        Some((texel, pixel))
    };
    if let Some(pos) = resp.hover_pos()
        && let Some((_, Some(p))) = to_pixel(pos)
    {
        cx.events.hover_pixel = Some(p);
    }
    if resp.clicked()
        && let Some(pos) = resp.interact_pointer_pos()
        && let Some((texel, pixel)) = to_pixel(pos)
    {
        cx.events.click = Some(ViewClick { pixel, texel, buffer });
    }
    // Shift + drag on an A/B view: the rectangle the metrics also measure.
    if selecting
        && let Some(pos) = resp.interact_pointer_pos()
        && let Some((_, Some(p))) = to_pixel(pos)
    {
        if resp.drag_started() || pane.rt.drag_start.is_none() {
            pane.rt.drag_start = Some(p);
        }
        if let Some(a) = pane.rt.drag_start {
            pane.rect = Some([a.0.min(p.0), a.1.min(p.1), a.0.max(p.0) + 1, a.1.max(p.1) + 1]);
            pane.rt.metrics_at = f64::NEG_INFINITY;
        }
    }
    if resp.drag_stopped() {
        pane.rt.drag_start = None;
    }
}

/// The A/B rectangle and the metrics (or why there are none) in the corner.
fn draw_ab(painter: &egui::Painter, at: &Placed, pane: &ViewPane, (fw, fh): (u32, u32)) {
    let (rect, disp) = (at.rect, at.disp);
    let ab = pane.spec.effective_ab();
    let side_by_side = ab.is_some_and(|a| a.mode == AbMode::SideBySide);
    if let Some([x0, y0, x1, y1]) = pane.rect.filter(|_| ab.is_some()) {
        let halves = if side_by_side { 2 } else { 1 };
        for k in 0..halves {
            let at = |x: u32, y: u32| {
                let u = x as f32 / fw as f32 / halves as f32 + k as f32 / halves as f32;
                disp.min + egui::vec2(u * disp.width(), y as f32 / fh as f32 * disp.height())
            };
            painter.rect_stroke(
                egui::Rect::from_min_max(at(x0, y0), at(x1, y1)),
                0.0,
                egui::Stroke::new(1.5, egui::Color32::from_rgb(255, 220, 0)),
                egui::StrokeKind::Outside,
            );
        }
    }
    let note = pane.rt.metrics_note.clone().filter(|_| ab.is_some());
    if let Some(n) = note {
        painter.text(
            rect.right_bottom() - egui::vec2(8.0, 8.0),
            egui::Align2::RIGHT_BOTTOM,
            n,
            egui::FontId::proportional(11.0),
            egui::Color32::from_gray(235),
        );
    } else if let Some((m, mr)) = pane.rt.metrics.filter(|_| ab.is_some()) {
        let mut text = format!(
            "A vs B: RMSE {:.3e} (rel. {:.3}) · SSIM {:.4} · FLIP {:.4} · mean ratio {:.3}",
            m.rmse, m.relative_rmse, m.ssim, m.flip, m.mean_ratio
        );
        if let (Some(r), Some([x0, y0, x1, y1])) = (mr, pane.rect) {
            text += &format!(
                "\nrectangle {}x{} at ({x0}, {y0}): RMSE {:.3e} (rel. {:.3}) · SSIM {:.4} · FLIP {:.4} · mean ratio {:.3}",
                x1 - x0,
                y1 - y0,
                r.rmse,
                r.relative_rmse,
                r.ssim,
                r.flip,
                r.mean_ratio
            );
        } else {
            text += "\nshift + drag: measure a rectangle too";
        }
        let galley = painter.layout(
            text,
            egui::FontId::proportional(11.0),
            egui::Color32::from_gray(235),
            rect.width() - 20.0,
        );
        let at = rect.right_bottom() - galley.size() - egui::vec2(8.0, 8.0);
        painter.rect_filled(
            egui::Rect::from_min_size(at, galley.size()).expand(4.0),
            3.0,
            egui::Color32::from_black_alpha(170),
        );
        painter.galley(at, galley, egui::Color32::WHITE);
    }
}

/// The pinned pixel, outlined (in both halves of a side-by-side view).
fn draw_pinned(
    cx: &PaneContext<'_>,
    painter: &egui::Painter,
    at: &Placed,
    buffer: ViewBuffer,
    side_by_side: bool,
) {
    let (disp, tw) = (at.disp, at.tw);
    let (fw, fh) = cx.renderer.size();
    if let Some((px, py)) = cx.pinned
        && !buffer.is_rsm_space()
    {
        let w = if side_by_side { 2 } else { 1 };
        for k in 0..w {
            let u = (px as f32 + 0.5) / fw as f32 / w as f32 + k as f32 / w as f32;
            let v = (py as f32 + 0.5) / fh as f32;
            let c = disp.min + egui::vec2(u * disp.width(), v * disp.height());
            let r = (disp.width() / tw as f32).max(4.0);
            painter.rect_stroke(
                egui::Rect::from_center_size(c, egui::vec2(r, r)),
                0.0,
                egui::Stroke::new(1.5, egui::Color32::from_rgb(255, 60, 200)),
                egui::StrokeKind::Outside,
            );
        }
    }
}

/// World-space overlays (the method's primitives) projected onto a single-image camera view.
fn draw_overlay(cx: &PaneContext<'_>, painter: &egui::Painter, at: &Placed) {
    let disp = at.disp;
    let project = |p: glam::Vec3| -> Option<egui::Pos2> {
        let c = cx.view_proj * p.extend(1.0);
        if c.w <= 1e-6 {
            return None;
        }
        let (u, v) = (c.x / c.w * 0.5 + 0.5, 0.5 - c.y / c.w * 0.5);
        Some(disp.min + egui::vec2(u * disp.width(), v * disp.height()))
    };
    let line = |a: glam::Vec3, b: glam::Vec3, c: egui::Color32, w: f32| {
        if let (Some(pa), Some(pb)) = (project(a), project(b)) {
            painter.line_segment([pa, pb], egui::Stroke::new(w, c));
        }
    };
    let ellipse = |center: glam::Vec3, axes: [glam::Vec3; 2], color: egui::Color32, w: f32| {
        let n = 48;
        let at = |k: u32| {
            let a = k as f32 / n as f32 * std::f32::consts::TAU;
            center + axes[0] * a.cos() + axes[1] * a.sin()
        };
        for k in 0..n {
            line(at(k), at(k + 1), color, w);
        }
    };
    for prim in cx.overlay {
        match (*prim).map_color(color32) {
            Prim::Point(p, c) => {
                if let Some(q) = project(p) {
                    painter.circle_filled(q, 3.0, c);
                }
            }
            Prim::Line(a, b, c) => line(a, b, c, 1.0),
            Prim::Box(lo, hi, c) => {
                let corner = |i: u32| {
                    glam::Vec3::new(
                        if i & 1 == 0 { lo.x } else { hi.x },
                        if i & 2 == 0 { lo.y } else { hi.y },
                        if i & 4 == 0 { lo.z } else { hi.z },
                    )
                };
                for i in 0..8u32 {
                    for bit in [1, 2, 4] {
                        if i & bit == 0 {
                            line(corner(i), corner(i | bit), c, 1.0);
                        }
                    }
                }
            }
            Prim::Ellipse { center, axes, color } => ellipse(center, axes, color, 1.5),
            Prim::Sphere {
                center,
                radius,
                color,
            } => {
                // Three great circles.
                let (x, y, z) = (
                    glam::Vec3::X * radius,
                    glam::Vec3::Y * radius,
                    glam::Vec3::Z * radius,
                );
                for axes in [[x, y], [y, z], [z, x]] {
                    ellipse(center, axes, color, 1.0);
                }
            }
        }
    }
}

/// On a view of the comparison's ground truth while it converges: how far it got, as a bar
/// and a line across the view's top (the image meanwhile shows the VPLs so far, scaled to
/// all of them).
fn draw_truth_progress(cx: &PaneContext<'_>, painter: &egui::Painter, rect: egui::Rect, pane: &ViewPane) {
    let gt = |s: AbSource| matches!(s, AbSource::GroundTruthIndirect | AbSource::GroundTruthFinal);
    let shows_truth = matches!(
        pane.spec.buffer,
        ViewBuffer::GroundTruthFinal | ViewBuffer::GroundTruthIndirect
    ) || pane.spec.effective_ab().is_some_and(|ab| gt(ab.a) || gt(ab.b));
    if !shows_truth {
        return;
    }
    let Some(p) = cx.renderer.compare_progress().filter(|p| !p.finished()) else {
        return;
    };
    let f = p.fraction();
    let bar = egui::Rect::from_min_size(
        rect.left_top() + egui::vec2(8.0, 26.0),
        egui::vec2(rect.width() - 16.0, 5.0),
    );
    painter.rect_filled(bar, 2.0, egui::Color32::from_black_alpha(160));
    painter.rect_filled(
        egui::Rect::from_min_size(bar.min, egui::vec2(bar.width() * f, bar.height())),
        2.0,
        egui::Color32::from_rgb(90, 170, 255),
    );
    let galley = painter.layout(
        format!(
            "ground truth converging: {:.0}% of {} VPLs (the VPLs so far, scaled to all)",
            100.0 * f,
            p.total
        ),
        egui::FontId::proportional(11.0),
        egui::Color32::from_gray(235),
        bar.width(),
    );
    let at = bar.left_bottom() + egui::vec2(0.0, 4.0);
    painter.rect_filled(
        egui::Rect::from_min_size(at, galley.size()).expand(2.0),
        2.0,
        egui::Color32::from_black_alpha(150),
    );
    painter.galley(at, galley, egui::Color32::WHITE);
}
