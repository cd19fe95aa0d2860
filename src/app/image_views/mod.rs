//! Docked image views (egui_tiles): any number of panes, each showing any buffer by name with
//! its own look (exposure, tonemap, channel, false colour, NaN highlight) or an A/B comparison,
//! all sharing one zoom and pan (nearest-neighbour when magnified). Panes can be dragged
//! (handle at the left of each toolbar), split, tabbed and closed; the layout is saved with the
//! app state. A pane reports what the user did (camera drags, hovered and clicked pixels,
//! exports) as [`ViewEvents`]; the app applies them.

mod pane;
mod toolbar;

use egui_tiles::{Behavior, TileId, UiResponse};
use glam::Vec2;
use pane::view_pane_ui;
use serde::{Deserialize, Serialize};

use super::viewport_texture::ViewportTexture;
use crate::base::traversal::TraversalStats;
use crate::gpu::views::{AbMode, AbSource, Channel, ViewSpec};
use crate::renderer::Renderer;
use crate::settings::{DisplaySettings, Tonemap, ViewBuffer};

/// One image view.
#[derive(Serialize, Deserialize)]
pub struct ViewPane {
    /// Stable number (titles, labels; the lowest is the main view).
    pub id: u32,
    pub spec: ViewSpec,
    /// A/B views: the rectangle (frame pixels x0, y0, x1, y1) measured besides the whole image
    /// (shift + drag selects it).
    #[serde(default)]
    pub rect: Option<[u32; 4]>,
    #[serde(skip)]
    pub rt: PaneRuntime,
}

/// Per-frame state of a pane (not saved).
#[derive(Default)]
pub struct PaneRuntime {
    pub texture: ViewportTexture,
    /// Its texture in the renderer's last `render_views` (None: not rendered, e.g. a hidden tab).
    pub slot: Option<usize>,
    /// Size of its image area in physical pixels at the last layout.
    pub size_px: Option<egui::Vec2>,
    /// A/B views: metrics of the whole pair and of the rectangle, and when they were taken.
    pub metrics: Option<(crate::metrics::Metrics, Option<crate::metrics::Metrics>)>,
    pub metrics_at: f64,
    /// Why there are no metrics (e.g. the ground truth is still accumulating).
    pub metrics_note: Option<String>,
    drag_start: Option<(u32, u32)>,
}

/// The zoom and pan all views share: `zoom` 1 fits the image, `center` is the image point
/// (0..1 each axis) at the centre of every pane.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ViewTransform {
    pub zoom: f32,
    pub center: [f32; 2],
}

impl Default for ViewTransform {
    fn default() -> Self {
        Self {
            zoom: 1.0,
            center: [0.5, 0.5],
        }
    }
}

/// The saved layout: the tile tree of views and the shared transform.
#[derive(Serialize, Deserialize)]
pub struct Layout {
    pub tree: egui_tiles::Tree<ViewPane>,
    pub transform: ViewTransform,
    pub next_id: u32,
}

impl Layout {
    /// A grid of views of `buffers` (at least one: final).
    pub fn new(buffers: &[ViewBuffer], d: &DisplaySettings) -> Self {
        let buffers = if buffers.is_empty() {
            &[ViewBuffer::Final][..]
        } else {
            buffers
        };
        let panes: Vec<ViewPane> = buffers
            .iter()
            .enumerate()
            .map(|(i, b)| ViewPane {
                id: i as u32 + 1,
                spec: ViewSpec::new(*b, d),
                rect: None,
                rt: PaneRuntime::default(),
            })
            .collect();
        Self {
            tree: egui_tiles::Tree::new_grid(egui::Id::unique("image_views"), panes),
            transform: ViewTransform::default(),
            next_id: buffers.len() as u32 + 1,
        }
    }

    /// Adds a view beside the others.
    pub fn add_view(&mut self, spec: ViewSpec) -> u32 {
        let id = self.next_id;
        self.next_id += 1;
        let tile = self.tree.tiles.insert_pane(ViewPane {
            id,
            spec,
            rect: None,
            rt: PaneRuntime::default(),
        });
        match self.tree.root() {
            Some(root) => {
                if let Some(egui_tiles::Tile::Container(c)) = self.tree.tiles.get_mut(root) {
                    c.add_child(tile);
                } else {
                    let grid = self.tree.tiles.insert_grid_tile(vec![root, tile]);
                    self.tree.root = Some(grid);
                }
            }
            None => self.tree.root = Some(tile),
        }
        id
    }

    /// Pane tiles in id order.
    fn pane_ids(&self) -> Vec<(u32, TileId)> {
        let mut v: Vec<(u32, TileId)> = self
            .tree
            .tiles
            .iter()
            .filter_map(|(tid, t)| match t {
                egui_tiles::Tile::Pane(p) => Some((p.id, *tid)),
                _ => None,
            })
            .collect();
        v.sort_by_key(|(id, _)| *id);
        v
    }

    pub fn view_count(&self) -> usize {
        self.pane_ids().len()
    }

    /// The main view (lowest id): the buffer selector of the side panel, hovered timings.
    pub fn main_pane_mut(&mut self) -> Option<&mut ViewPane> {
        let (_, tid) = *self.pane_ids().first()?;
        match self.tree.tiles.get_mut(tid) {
            Some(egui_tiles::Tile::Pane(p)) => Some(p),
            _ => None,
        }
    }

    pub fn main_pane(&self) -> Option<&ViewPane> {
        let (_, tid) = *self.pane_ids().first()?;
        self.tree.tiles.get_pane(&tid)
    }

    /// Every pane, in id order.
    pub fn panes_mut(&mut self) -> Vec<&mut ViewPane> {
        let order: Vec<u32> = self.pane_ids().into_iter().map(|(id, _)| id).collect();
        let mut panes: Vec<&mut ViewPane> = self
            .tree
            .tiles
            .tiles_mut()
            .filter_map(|t| match t {
                egui_tiles::Tile::Pane(p) => Some(p),
                _ => None,
            })
            .collect();
        panes.sort_by_key(|p| order.iter().position(|&i| i == p.id));
        panes
    }

    pub fn panes(&self) -> Vec<&ViewPane> {
        self.pane_ids()
            .into_iter()
            .filter_map(|(_, t)| self.tree.tiles.get_pane(&t))
            .collect()
    }

    /// The specs to render this frame (the visible panes, main view first; `main_override`
    /// replaces the main view's buffer) and each pane's slot.
    pub fn assign_slots(&mut self, main_override: Option<ViewBuffer>) -> Vec<ViewSpec> {
        let ids = self.pane_ids();
        let active = self.tree.active_tiles();
        let mut specs = Vec::new();
        for (k, (_, tid)) in ids.iter().enumerate() {
            let visible = self.tree.is_visible(*tid) && active.contains(tid);
            if let Some(egui_tiles::Tile::Pane(p)) = self.tree.tiles.get_mut(*tid) {
                if visible || (k == 0 && specs.is_empty()) {
                    let mut spec = p.spec;
                    if k == 0
                        && let Some(b) = main_override
                    {
                        spec.buffer = b;
                    }
                    p.rt.slot = Some(specs.len());
                    specs.push(spec);
                } else {
                    p.rt.slot = None;
                }
            }
        }
        if specs.is_empty() {
            specs.push(ViewSpec::default());
        }
        specs
    }

    /// The largest image area of the views (physical pixels), for the render resolution.
    pub fn largest_view_px(&self) -> Option<egui::Vec2> {
        self.panes()
            .iter()
            .filter(|p| p.rt.slot.is_some())
            .filter_map(|p| p.rt.size_px)
            .reduce(|a, b| a.max(b))
    }
}

/// What to export from a view.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ExportKind {
    /// The view as displayed (PNG).
    Png,
    /// The linear buffer behind it (EXR; both images of an A/B view).
    Exr,
}

/// A click on a view's image.
#[derive(Clone, Copy, Debug)]
pub struct ViewClick {
    /// Frame pixel (camera-space views).
    pub pixel: Option<(u32, u32)>,
    /// Texel of the view's texture.
    pub texel: (u32, u32),
    pub buffer: ViewBuffer,
}

/// What the user did in the views this frame.
#[derive(Default)]
pub struct ViewEvents {
    /// Drag delta (points) and whether with the primary button.
    pub camera_drag: Option<(Vec2, bool)>,
    pub scroll: f32,
    /// A view is hovered (fly-mode keys apply).
    pub hovered: bool,
    pub hover_pixel: Option<(u32, u32)>,
    pub click: Option<ViewClick>,
    pub export: Option<(usize, ViewSpec, ExportKind)>,
    pub snapshot: Option<AbSource>,
}

pub use crate::methods::overlay::{Prim, Rgba8};

/// An overlay colour as egui draws it.
pub fn color32(c: Rgba8) -> egui::Color32 {
    let [r, g, b, a] = c.0;
    egui::Color32::from_rgba_unmultiplied(r, g, b, a)
}

/// An egui colour as an overlay colour.
pub fn rgba8(c: egui::Color32) -> Rgba8 {
    Rgba8(c.to_srgba_unmultiplied())
}

/// Everything a pane needs to draw itself.
pub struct PaneContext<'a> {
    pub renderer: &'a Renderer,
    pub render_state: &'a egui_wgpu::RenderState,
    pub transform: &'a mut ViewTransform,
    pub events: &'a mut ViewEvents,
    /// Smooth an upscaled render (render scale < 1) unless magnified.
    pub linear_filter: bool,
    pub stats: Option<TraversalStats>,
    pub display: &'a DisplaySettings,
    pub snapshots: &'a [String],
    pub pinned: Option<(u32, u32)>,
    /// World-space overlays and the camera's view-projection (frame aspect).
    pub overlay: &'a [Prim],
    pub view_proj: glam::Mat4,
}

impl Behavior<ViewPane> for PaneContext<'_> {
    fn pane_ui(&mut self, ui: &mut egui::Ui, _tile_id: TileId, pane: &mut ViewPane) -> UiResponse {
        view_pane_ui(self, ui, pane)
    }

    fn tab_title_for_pane(&mut self, pane: &ViewPane) -> egui::WidgetText {
        format!("view {} · {}", pane.id, pane.spec.buffer.name()).into()
    }

    fn is_tab_closable(&self, tiles: &egui_tiles::Tiles<ViewPane>, _tile_id: TileId) -> bool {
        tiles
            .tiles()
            .filter(|t| matches!(t, egui_tiles::Tile::Pane(_)))
            .count()
            > 1
    }

    fn on_tab_close(&mut self, tiles: &mut egui_tiles::Tiles<ViewPane>, tile_id: TileId) -> bool {
        if let Some(egui_tiles::Tile::Pane(p)) = tiles.get_mut(tile_id) {
            p.rt.texture.free(self.render_state);
        }
        true
    }

    fn simplification_options(&self) -> egui_tiles::SimplificationOptions {
        egui_tiles::SimplificationOptions {
            all_panes_must_have_tabs: true,
            ..Default::default()
        }
    }
}
