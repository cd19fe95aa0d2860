//! The tool dock: the pixel story, pixel values, cut inspector and GPU timings as docked
//! panes (egui_tiles) in a panel right of the views, by default; each can float as a window
//! and dock again. Which tools are open stays with their owners (`StoryPanel::show`,
//! `PixelInspect::show`, the cut inspector, `TimingsPanel::show`); the dock follows them.

use egui_tiles::{Behavior, TileId, UiResponse};

use super::WorkbenchApp;
use crate::settings::ViewBuffer;

/// A tool pane.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Tool {
    Story,
    PixelValues,
    CutInspector,
    Timings,
}

impl Tool {
    pub const ALL: [Tool; 4] = [Tool::Story, Tool::PixelValues, Tool::CutInspector, Tool::Timings];
    pub fn title(self) -> &'static str {
        match self {
            Tool::Story => "Pixel story",
            Tool::PixelValues => "Pixel values",
            Tool::CutInspector => "Cut inspector",
            Tool::Timings => "GPU timings",
        }
    }
}

/// The docked tools' layout and the floating ones.
pub struct ToolDock {
    pub tree: egui_tiles::Tree<Tool>,
    pub floating: Vec<Tool>,
}

impl Default for ToolDock {
    fn default() -> Self {
        Self {
            tree: egui_tiles::Tree::empty(egui::Id::unique("tool_dock")),
            floating: Vec::new(),
        }
    }
}

impl ToolDock {
    /// The docked tools.
    pub fn docked(&self) -> Vec<Tool> {
        self.tree
            .tiles
            .iter()
            .filter_map(|(_, t)| match t {
                egui_tiles::Tile::Pane(p) => Some(*p),
                _ => None,
            })
            .collect()
    }

    /// Docks the open tools that do not float (stacked top to bottom, newest last) and
    /// removes the closed ones.
    pub fn sync(&mut self, open: &[Tool]) {
        self.floating.retain(|t| open.contains(t));
        let want: Vec<Tool> = open
            .iter()
            .copied()
            .filter(|t| !self.floating.contains(t))
            .collect();
        let stale: Vec<TileId> = self
            .tree
            .tiles
            .iter()
            .filter_map(|(id, t)| match t {
                egui_tiles::Tile::Pane(p) if !want.contains(p) => Some(*id),
                _ => None,
            })
            .collect();
        for id in stale {
            self.tree.remove_recursively(id);
        }
        let have = self.docked();
        for t in want {
            if have.contains(&t) {
                continue;
            }
            let tile = self.tree.tiles.insert_pane(t);
            match self.tree.root() {
                Some(root) => {
                    if let Some(egui_tiles::Tile::Container(c)) = self.tree.tiles.get_mut(root) {
                        c.add_child(tile);
                    } else {
                        let col = self.tree.tiles.insert_vertical_tile(vec![root, tile]);
                        self.tree.root = Some(col);
                    }
                }
                None => self.tree.root = Some(tile),
            }
        }
    }
}

/// What a tool pane can reach: the app (the dock's tree is moved out while it draws).
struct DockBehavior<'a> {
    app: &'a mut WorkbenchApp,
    /// Tools whose float button was pressed, or whose tab was closed.
    float: Vec<Tool>,
    close: Vec<Tool>,
    /// The view the timings pane asks to show (a hovered pass).
    hover: Option<ViewBuffer>,
}

impl Behavior<Tool> for DockBehavior<'_> {
    fn pane_ui(&mut self, ui: &mut egui::Ui, _tile_id: TileId, tool: &mut Tool) -> UiResponse {
        let mut response = UiResponse::None;
        ui.horizontal(|ui| {
            let handle = ui
                .add(egui::Button::new("::").sense(egui::Sense::drag()))
                .on_hover_text("drag to move this tool in the dock");
            if handle.drag_started() {
                response = UiResponse::DragStarted;
            }
            ui.strong(tool.title());
            if ui
                .small_button("float")
                .on_hover_text("show as a floating window")
                .clicked()
            {
                self.float.push(*tool);
            }
            if ui.small_button("close").clicked() {
                self.close.push(*tool);
            }
        });
        ui.separator();
        egui::ScrollArea::both()
            .id_salt(("tool_scroll", *tool as u8))
            .auto_shrink([false, false])
            .show(ui, |ui| {
                if let Some(v) = self.app.tool_contents(*tool, ui) {
                    self.hover = Some(v);
                }
            });
        response
    }

    fn tab_title_for_pane(&mut self, tool: &Tool) -> egui::WidgetText {
        tool.title().into()
    }

    fn is_tab_closable(&self, _tiles: &egui_tiles::Tiles<Tool>, _tile_id: TileId) -> bool {
        true
    }

    fn on_tab_close(&mut self, tiles: &mut egui_tiles::Tiles<Tool>, tile_id: TileId) -> bool {
        if let Some(egui_tiles::Tile::Pane(t)) = tiles.get(tile_id) {
            self.close.push(*t);
        }
        true
    }

    fn simplification_options(&self) -> egui_tiles::SimplificationOptions {
        egui_tiles::SimplificationOptions {
            all_panes_must_have_tabs: false,
            ..Default::default()
        }
    }
}

impl WorkbenchApp {
    /// The open tools, in dock order.
    fn open_tools(&self) -> Vec<Tool> {
        Tool::ALL
            .into_iter()
            .filter(|t| match t {
                Tool::Story => self.story.show,
                Tool::PixelValues => self.pixel.show,
                Tool::CutInspector => self.cut_inspect.is_some(),
                Tool::Timings => self.timings_panel.show,
            })
            .collect()
    }

    fn close_tool(&mut self, tool: Tool) {
        match tool {
            Tool::Story => self.story.show = false,
            Tool::PixelValues => self.pixel.show = false,
            Tool::CutInspector => {
                self.cut_inspect = None;
                if let Some(r) = &mut self.renderer {
                    r.select_block(None);
                }
            }
            Tool::Timings => self.timings_panel.show = false,
        }
    }

    /// One tool's contents; the timings return the view of a hovered pass.
    pub(super) fn tool_contents(&mut self, tool: Tool, ui: &mut egui::Ui) -> Option<ViewBuffer> {
        match tool {
            Tool::Story => self.story.contents(ui),
            Tool::PixelValues => self.pixel_contents(ui),
            Tool::CutInspector => self.cut_contents(ui),
            Tool::Timings => return self.timings_panel.contents(ui),
        }
        None
    }

    /// The dock (a panel right of the views) while a tool is docked; returns the view a
    /// hovered timing asks for.
    pub(super) fn tool_dock(&mut self, ui: &mut egui::Ui) -> Option<ViewBuffer> {
        let open = self.open_tools();
        self.tools.sync(&open);
        if self.tools.docked().is_empty() {
            return None;
        }
        let mut tree = std::mem::replace(
            &mut self.tools.tree,
            egui_tiles::Tree::empty(egui::Id::unique("tool_dock_swap")),
        );
        let mut b = DockBehavior {
            app: self,
            float: Vec::new(),
            close: Vec::new(),
            hover: None,
        };
        egui::Panel::right("tool_dock")
            .default_size(360.0)
            .resizable(true)
            .show(ui, |ui| tree.ui(&mut b, ui));
        let (float, close, hover) = (b.float, b.close, b.hover);
        self.tools.tree = tree;
        for t in close {
            self.close_tool(t);
        }
        self.tools.floating.extend(float);
        hover
    }

    /// The floating tools as windows ("dock" puts one back); returns a hovered timing's view.
    pub(super) fn tool_windows(&mut self, ctx: &egui::Context) -> Option<ViewBuffer> {
        let mut hover = None;
        for tool in self.tools.floating.clone() {
            let mut open = true;
            let mut dock = false;
            egui::Window::new(tool.title())
                .open(&mut open)
                .default_width(460.0)
                .default_height(480.0)
                .vscroll(true)
                .show(ctx, |ui| {
                    if ui
                        .small_button("dock")
                        .on_hover_text("back into the tool dock")
                        .clicked()
                    {
                        dock = true;
                    }
                    if let Some(v) = self.tool_contents(tool, ui) {
                        hover = Some(v);
                    }
                });
            if dock {
                self.tools.floating.retain(|t| *t != tool);
            }
            if !open {
                self.close_tool(tool);
            }
        }
        hover
    }
}
