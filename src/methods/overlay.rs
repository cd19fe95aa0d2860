//! World-space primitives a method (or the pixel story) draws over the camera views, and a
//! method's overlay for the pinned pixel (light culling: the range spheres of the pixel's
//! tile list). The GUI projects them with the frame's camera (`app::image_views`).

/// An sRGB colour with straight (unmultiplied) alpha; the GUI draws it as egui's `Color32`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Rgba8(pub [u8; 4]);

impl Rgba8 {
    pub const WHITE: Rgba8 = Rgba8([255; 4]);

    pub const fn rgb(r: u8, g: u8, b: u8) -> Rgba8 {
        Rgba8([r, g, b, 255])
    }

    pub const fn rgba(r: u8, g: u8, b: u8, a: u8) -> Rgba8 {
        Rgba8([r, g, b, a])
    }
}

/// A world-space overlay primitive drawn over the camera views, in colours `C`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Prim<C = Rgba8> {
    Point(glam::Vec3, C),
    Line(glam::Vec3, glam::Vec3, C),
    /// Axis-aligned box (min, max).
    Box(glam::Vec3, glam::Vec3, C),
    /// Ellipse centre + the two semi-axes (world vectors).
    Ellipse {
        center: glam::Vec3,
        axes: [glam::Vec3; 2],
        color: C,
    },
    /// A sphere, drawn as its three axis-aligned great circles.
    Sphere {
        center: glam::Vec3,
        radius: f32,
        color: C,
    },
}

impl<C> Prim<C> {
    /// The same primitive in another colour type (the GUI's).
    pub fn map_color<D>(self, f: impl Fn(C) -> D) -> Prim<D> {
        match self {
            Prim::Point(p, c) => Prim::Point(p, f(c)),
            Prim::Line(a, b, c) => Prim::Line(a, b, f(c)),
            Prim::Box(lo, hi, c) => Prim::Box(lo, hi, f(c)),
            Prim::Ellipse { center, axes, color } => Prim::Ellipse {
                center,
                axes,
                color: f(color),
            },
            Prim::Sphere {
                center,
                radius,
                color,
            } => Prim::Sphere {
                center,
                radius,
                color: f(color),
            },
        }
    }
}

/// What a method shows of the pinned pixel besides (or instead of) a sample or cut story:
/// a table and world-space primitives.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MethodOverlay {
    /// A title line.
    pub title: String,
    /// (what, value) rows.
    pub rows: Vec<(String, String)>,
    /// What the colours of `prims` mean.
    pub key: String,
    pub prims: Vec<Prim>,
}
