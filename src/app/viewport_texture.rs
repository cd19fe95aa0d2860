//! The one bridge between the renderer and egui: hands the renderer's `Rgba8Unorm` view
//! texture to `egui_wgpu` (registered once, re-pointed when the texture is recreated).

pub struct ViewportTexture {
    id: Option<egui::TextureId>,
    generation: u64,
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
        }
    }

    /// The egui texture id showing `view` (registering or updating it when `generation` changed).
    pub fn update(
        &mut self,
        render_state: &egui_wgpu::RenderState,
        view: &wgpu::TextureView,
        generation: u64,
    ) -> egui::TextureId {
        let mut renderer = render_state.renderer.write();
        match self.id {
            Some(id) if self.generation == generation => id,
            Some(id) => {
                renderer.update_egui_texture_from_wgpu_texture(
                    &render_state.device,
                    view,
                    wgpu::FilterMode::Nearest,
                    id,
                );
                self.generation = generation;
                id
            }
            None => {
                let id =
                    renderer.register_native_texture(&render_state.device, view, wgpu::FilterMode::Nearest);
                self.id = Some(id);
                self.generation = generation;
                id
            }
        }
    }

    /// Forgets the texture (after the renderer was replaced).
    pub fn reset(&mut self, render_state: &egui_wgpu::RenderState) {
        if let Some(id) = self.id.take() {
            render_state.renderer.write().free_texture(&id);
        }
        self.generation = u64::MAX;
    }
}
