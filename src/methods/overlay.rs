//! World-space primitives a method (or the pixel story) draws over the camera views, and a
//! method's overlay for the pinned pixel (light culling: the range spheres of the pixel's
//! tile list). The GUI projects them with the frame's camera (`app::image_views`).

/// A world-space overlay primitive drawn over the camera views.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Prim {
    Point(glam::Vec3, egui::Color32),
    Line(glam::Vec3, glam::Vec3, egui::Color32),
    /// Axis-aligned box (min, max).
    Box(glam::Vec3, glam::Vec3, egui::Color32),
    /// Ellipse centre + the two semi-axes (world vectors).
    Ellipse {
        center: glam::Vec3,
        axes: [glam::Vec3; 2],
        color: egui::Color32,
    },
    /// A sphere, drawn as its three axis-aligned great circles.
    Sphere {
        center: glam::Vec3,
        radius: f32,
        color: egui::Color32,
    },
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
