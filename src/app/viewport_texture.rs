//! The one bridge between the renderer and egui: hands the renderer's `Rgba8Unorm` view
//! texture to `egui_wgpu` (registered once, re-pointed when the texture is recreated).

pub struct ViewportTexture {
    id: Option<egui::TextureId>,
    generation: u64,
    filter: wgpu::FilterMode,
}

impl Default for ViewportTexture {
    fn default() -> Self {
        Self::new()
    }
}

impl ViewportTexture {
    pub fn new() -> Self {
        Self {
            id: None,
            generation: u64::MAX,
            filter: wgpu::FilterMode::Nearest,
        }
    }

    /// The egui texture id showing `view` (registering or updating it when `generation` or the
    /// filter changed). Nearest filtering shows render pixels as they are; linear smooths an
    /// upscaled low-resolution render.
    pub fn update(
        &mut self,
        render_state: &egui_wgpu::RenderState,
        view: &wgpu::TextureView,
        generation: u64,
        filter: wgpu::FilterMode,
    ) -> egui::TextureId {
        let mut renderer = render_state.renderer.write();
        match self.id {
            Some(id) if self.generation == generation && self.filter == filter => id,
            Some(id) => {
                renderer.update_egui_texture_from_wgpu_texture(&render_state.device, view, filter, id);
                self.generation = generation;
                self.filter = filter;
                id
            }
            None => {
                let id = renderer.register_native_texture(&render_state.device, view, filter);
                self.id = Some(id);
                self.generation = generation;
                self.filter = filter;
                id
            }
        }
    }

    /// Unregisters the texture (when its view closes).
    pub fn free(&mut self, render_state: &egui_wgpu::RenderState) {
        if let Some(id) = self.id.take() {
            render_state.renderer.write().free_texture(&id);
        }
        self.generation = u64::MAX;
    }
}
