//! The linear float image every layer passes around (readbacks, EXRs, metrics, sheets).

/// A linear RGBA float image, row-major, top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct ImageF32 {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<[f32; 4]>,
}

impl ImageF32 {
    pub fn get(&self, x: u32, y: u32) -> [f32; 4] {
        self.pixels[(y * self.width + x) as usize]
    }
    /// Mean of the RGB channels over all pixels.
    pub fn mean_rgb(&self) -> [f64; 3] {
        let mut s = [0f64; 3];
        for p in &self.pixels {
            for c in 0..3 {
                s[c] += p[c] as f64;
            }
        }
        let n = self.pixels.len().max(1) as f64;
        s.map(|v| v / n)
    }
}
