//! Axis-aligned boxes: the tank, blocks, obstacles and the bounds of every shape.

/// An axis-aligned box (3 components; in 2D the third is 0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aabb {
    pub min: [f64; 3],
    pub max: [f64; 3],
}
