//! Axis-aligned rectangles in a light plane's (u, v) frame.

use glam::Vec2;

/// A rectangle `[u_min, u_max] x [v_min, v_max]` in plane coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rect {
    /// Left edge (smallest u).
    pub u_min: f32,
    /// Right edge.
    pub u_max: f32,
    /// Bottom edge (smallest v).
    pub v_min: f32,
    /// Top edge.
    pub v_max: f32,
}

impl Rect {
    /// True when `p` is inside or on the boundary.
    #[inline]
    pub fn contains(&self, p: Vec2) -> bool {
        p.x >= self.u_min && p.x <= self.u_max && p.y >= self.v_min && p.y <= self.v_max
    }

    /// Width along u.
    pub fn width(&self) -> f32 {
        self.u_max - self.u_min
    }

    /// Height along v.
    pub fn height(&self) -> f32 {
        self.v_max - self.v_min
    }

    /// Centre.
    pub fn center(&self) -> Vec2 {
        Vec2::new(
            0.5 * (self.u_min + self.u_max),
            0.5 * (self.v_min + self.v_max),
        )
    }

    /// True when the two rectangles share some area.
    pub fn overlaps(&self, other: &Rect) -> bool {
        self.u_min < other.u_max
            && other.u_min < self.u_max
            && self.v_min < other.v_max
            && other.v_min < self.v_max
    }

    /// The edge on `side`.
    pub fn edge(&self, side: super::EdgeSide) -> f32 {
        match side {
            super::EdgeSide::Left => self.u_min,
            super::EdgeSide::Right => self.u_max,
            super::EdgeSide::Bottom => self.v_min,
            super::EdgeSide::Top => self.v_max,
        }
    }

    /// The same rectangle with the edge on `side` moved to `value`.
    pub fn with_edge(mut self, side: super::EdgeSide, value: f32) -> Self {
        match side {
            super::EdgeSide::Left => self.u_min = value,
            super::EdgeSide::Right => self.u_max = value,
            super::EdgeSide::Bottom => self.v_min = value,
            super::EdgeSide::Top => self.v_max = value,
        }
        self
    }
}
