//! What a frame's rays see of the skin ([`SurfaceHits`]): a leaf the ground truth, the
//! photometric model and its fit share.

/// The surface seen along every ray of a frame, sensor frame.
#[derive(Debug, Clone, PartialEq)]
pub struct SurfaceHits {
    /// Distance along the ray from its start (the camera centre; for bent rays their start in
    /// the last medium, [`crate::groundtruth::rays::PixelRays::origin`]), mm; NaN where the
    /// ray misses the skin.
    pub t_mm: Vec<f64>,
    /// Unit normal of the elastomer surface at the hit, pointing out of the elastomer (away
    /// from the sensor's inside), sensor frame; NaN where the ray misses.
    pub normal: Vec<[f64; 3]>,
    /// The hit is on a protrusion (the skin is pushed in there).
    pub contact: Vec<bool>,
    /// Where the ray leaves the sensor body when it misses the skin (below the base plane),
    /// mm, else equal to `t_mm`: the limit for protrusion hits.
    pub t_exit_mm: Vec<f64>,
}

impl SurfaceHits {
    /// Number of pixels that see the skin.
    pub fn valid_count(&self) -> usize {
        self.t_mm.iter().filter(|t| t.is_finite()).count()
    }
}
