//! PNG plots of the harness (plotters, drawn into a buffer and written with `image`; text in
//! the Hack font egui ships, rasterised by ab_glyph).

use std::{path::Path, sync::Once};

use anyhow::{Context, anyhow};
use plotters::{
    coord::{
        Shift,
        ranged1d::{AsRangedCoord, ValueFormatter},
    },
    prelude::*,
};

const SIZE: (u32, u32) = (720, 450);

fn fonts() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // Fails only for a broken font file, which the crate ships.
        let _ = plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            epaint_default_fonts::HACK_REGULAR,
        );
    });
}

/// The colour of series `i` (the same method keeps its colour across plots).
pub fn color(i: usize) -> RGBColor {
    const C: [RGBColor; 10] = [
        RGBColor(31, 119, 180),
        RGBColor(214, 39, 40),
        RGBColor(44, 160, 44),
        RGBColor(148, 103, 189),
        RGBColor(255, 127, 14),
        RGBColor(23, 190, 207),
        RGBColor(140, 86, 75),
        RGBColor(227, 119, 194),
        RGBColor(127, 127, 127),
        RGBColor(188, 189, 34),
    ];
    C[i % C.len()]
}

/// One line of a plot: a name, its colour index and its points.
pub struct Series {
    pub name: String,
    pub color: usize,
    pub points: Vec<(f64, f64)>,
}

/// Writes an RGB8 plot buffer of `size` as a PNG.
fn write(path: &Path, size: (u32, u32), buf: &[u8]) -> anyhow::Result<()> {
    let rgba: Vec<u8> = buf
        .chunks_exact(3)
        .flat_map(|c| [c[0], c[1], c[2], 255])
        .collect();
    crate::export::write_png(path, size.0, size.1, &rgba)
        .with_context(|| format!("cannot write {}", path.display()))
}

fn range(values: impl Iterator<Item = f64>, log: bool) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite() && (!log || *v > 0.0)) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return if log { (0.1, 10.0) } else { (0.0, 1.0) };
    }
    if log {
        let (a, b) = (lo.log10(), hi.log10());
        let pad = ((b - a) * 0.08).max(0.05);
        (10f64.powf(a - pad), 10f64.powf(b + pad))
    } else {
        let pad = ((hi - lo) * 0.08).max(hi.abs() * 0.05).max(1e-9);
        (lo - pad, hi + pad)
    }
}

fn draw_lines<X, Y>(
    root: &DrawingArea<BitMapBackend<'_>, Shift>,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
    x: X,
    y: Y,
) -> anyhow::Result<()>
where
    X: AsRangedCoord<Value = f64>,
    Y: AsRangedCoord<Value = f64>,
    X::CoordDescType: ValueFormatter<f64>,
    Y::CoordDescType: ValueFormatter<f64>,
{
    let e = |e: DrawingAreaErrorKind<_>| anyhow!("plot: {e:?}");
    let mut chart = ChartBuilder::on(root)
        .caption(title, ("sans-serif", 20))
        .margin(14)
        .x_label_area_size(44)
        .y_label_area_size(70)
        .build_cartesian_2d(x, y)
        .map_err(e)?;
    chart
        .configure_mesh()
        .x_desc(x_label)
        .y_desc(y_label)
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 15))
        .light_line_style(RGBColor(235, 235, 235))
        .draw()
        .map_err(e)?;
    for s in series {
        let c = color(s.color);
        let pts: Vec<(f64, f64)> = s
            .points
            .iter()
            .copied()
            .filter(|(a, b)| a.is_finite() && b.is_finite())
            .collect();
        chart
            .draw_series(LineSeries::new(pts.clone(), c.stroke_width(2)))
            .map_err(e)?
            .label(s.name.clone())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2)));
        chart
            .draw_series(pts.iter().map(|p| Circle::new(*p, 4, c.filled())))
            .map_err(e)?;
    }
    chart
        .configure_series_labels()
        .label_font(("sans-serif", 14))
        .background_style(WHITE.mix(0.85))
        .border_style(RGBColor(160, 160, 160))
        .position(SeriesLabelPosition::UpperRight)
        .draw()
        .map_err(e)?;
    Ok(())
}

/// A line plot with markers; either axis may be logarithmic.
pub fn lines(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
    log_x: bool,
    log_y: bool,
) -> anyhow::Result<()> {
    fonts();
    let mut buf = vec![0u8; (SIZE.0 * SIZE.1 * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(|e| anyhow!("plot: {e:?}"))?;
        let xs = range(series.iter().flat_map(|s| s.points.iter().map(|p| p.0)), log_x);
        let ys = range(series.iter().flat_map(|s| s.points.iter().map(|p| p.1)), log_y);
        match (log_x, log_y) {
            (false, false) => draw_lines(&root, title, x_label, y_label, series, xs.0..xs.1, ys.0..ys.1)?,
            (true, false) => draw_lines(
                &root,
                title,
                x_label,
                y_label,
                series,
                (xs.0..xs.1).log_scale(),
                ys.0..ys.1,
            )?,
            (false, true) => draw_lines(
                &root,
                title,
                x_label,
                y_label,
                series,
                xs.0..xs.1,
                (ys.0..ys.1).log_scale(),
            )?,
            (true, true) => draw_lines(
                &root,
                title,
                x_label,
                y_label,
                series,
                (xs.0..xs.1).log_scale(),
                (ys.0..ys.1).log_scale(),
            )?,
        }
        root.present().map_err(|e| anyhow!("plot: {e:?}"))?;
    }
    write(path, SIZE, &buf)
}

/// One bar: category label, value, spread (drawn as an error bar when > 0), colour index.
pub struct Bar {
    pub label: String,
    pub value: f64,
    pub spread: f64,
    pub color: usize,
}

fn draw_bars<Y>(
    root: &DrawingArea<BitMapBackend<'_>, Shift>,
    title: &str,
    y_label: &str,
    bars: &[Bar],
    y: Y,
    floor: f64,
) -> anyhow::Result<()>
where
    Y: AsRangedCoord<Value = f64>,
    Y::CoordDescType: ValueFormatter<f64>,
{
    let e = |e: DrawingAreaErrorKind<_>| anyhow!("plot: {e:?}");
    let n = bars.len();
    let labels: Vec<String> = bars.iter().map(|b| b.label.clone()).collect();
    let mut chart = ChartBuilder::on(root)
        .caption(title, ("sans-serif", 20))
        .margin(14)
        .x_label_area_size(44)
        .y_label_area_size(70)
        .build_cartesian_2d(-0.5f64..n as f64 - 0.5, y)
        .map_err(e)?;
    chart
        .configure_mesh()
        .disable_x_mesh()
        .x_labels(n + 2)
        .x_label_formatter(&|x| {
            let i = x.round();
            if (x - i).abs() < 1e-6 && i >= 0.0 && (i as usize) < labels.len() {
                labels[i as usize].clone()
            } else {
                String::new()
            }
        })
        .y_desc(y_label)
        .label_style(("sans-serif", 11))
        .axis_desc_style(("sans-serif", 15))
        .light_line_style(RGBColor(235, 235, 235))
        .draw()
        .map_err(e)?;
    for (i, b) in bars.iter().enumerate() {
        if !b.value.is_finite() {
            continue;
        }
        let x = i as f64;
        let c = color(b.color);
        chart
            .draw_series(std::iter::once(Rectangle::new(
                [(x - 0.35, floor), (x + 0.35, b.value.max(floor))],
                c.mix(0.85).filled(),
            )))
            .map_err(e)?;
        if b.spread > 0.0 && b.spread.is_finite() {
            let lo = (b.value - b.spread).max(floor);
            let hi = b.value + b.spread;
            chart
                .draw_series(std::iter::once(PathElement::new(
                    vec![(x, lo), (x, hi)],
                    BLACK.stroke_width(2),
                )))
                .map_err(e)?;
        }
    }
    Ok(())
}

/// A bar chart of categories (error bars = one standard deviation); `log_y` for values that
/// span decades (per-pass times).
pub fn bars(path: &Path, title: &str, y_label: &str, bars: &[Bar], log_y: bool) -> anyhow::Result<()> {
    fonts();
    let mut buf = vec![0u8; (SIZE.0 * SIZE.1 * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(|e| anyhow!("plot: {e:?}"))?;
        let vals = bars.iter().flat_map(|b| [b.value, b.value + b.spread.max(0.0)]);
        if log_y {
            let (lo, hi) = range(vals, true);
            draw_bars(&root, title, y_label, bars, (lo..hi).log_scale(), lo)?;
        } else {
            let (_, hi) = range(vals.chain([0.0]), false);
            draw_bars(&root, title, y_label, bars, 0.0..hi, 0.0)?;
        }
        root.present().map_err(|e| anyhow!("plot: {e:?}"))?;
    }
    write(path, SIZE, &buf)
}

/// A heat map image of per-pixel values with a shared scale `0..max` (NaN: dark grey), and a
/// colour bar with ticks drawn below it.
pub fn heatmap(path: &Path, title: &str, w: u32, h: u32, v: &[f32], max: f32) -> anyhow::Result<()> {
    fonts();
    let scale = (640.0 / w as f32).clamp(1.0, 8.0).floor() as u32;
    let (iw, ih) = (w * scale, h * scale);
    let size = (iw.max(360), ih + 80);
    let mut buf = vec![0u8; (size.0 * size.1 * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, size).into_drawing_area();
        let e = |e: DrawingAreaErrorKind<_>| anyhow!("plot: {e:?}");
        root.fill(&WHITE).map_err(e)?;
        let (img, bar) = root.split_vertically(ih);
        for y in 0..ih {
            for x in 0..iw {
                let t = v[((y / scale) * w + x / scale) as usize];
                let c = if t.is_finite() {
                    let c = crate::base::colormap::false_color((t / max.max(1e-6)).clamp(0.0, 1.0));
                    RGBColor((c[0] * 255.0) as u8, (c[1] * 255.0) as u8, (c[2] * 255.0) as u8)
                } else {
                    RGBColor(40, 40, 40)
                };
                img.draw_pixel((x as i32, y as i32), &c).map_err(e)?;
            }
        }
        let bw = size.0 - 40;
        for x in 0..bw {
            let c = crate::base::colormap::false_color(x as f32 / (bw - 1) as f32);
            let c = RGBColor((c[0] * 255.0) as u8, (c[1] * 255.0) as u8, (c[2] * 255.0) as u8);
            bar.draw(&Rectangle::new(
                [(20 + x as i32, 8), (21 + x as i32, 26)],
                c.filled(),
            ))
            .map_err(e)?;
        }
        let style = ("sans-serif", 14).into_font().color(&BLACK);
        for i in 0..=4 {
            let x = 20 + (i * (bw - 1) / 4) as i32;
            let label = format!("{:.1}", max * i as f32 / 4.0);
            bar.draw(&Text::new(label, (x - 8, 30), style.clone()))
                .map_err(e)?;
        }
        bar.draw(&Text::new(title.to_string(), (20, 52), style))
            .map_err(e)?;
        root.present().map_err(e)?;
    }
    write(path, size, &buf)
}
