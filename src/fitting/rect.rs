//! Axis-aligned rectangles in a light plane's (u, v) frame, and the box arithmetic the fits do
//! on them (a light's rectangle, a sample's kernel box, a pixel's bounding box, a region of
//! interest).

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
    /// The empty rectangle: inverted infinite bounds, so that it is the identity of
    /// [`union`](Self::union) and touches, overlaps and contains nothing.
    pub const EMPTY: Rect = Rect {
        u_min: f32::INFINITY,
        u_max: f32::NEG_INFINITY,
        v_min: f32::INFINITY,
        v_max: f32::NEG_INFINITY,
    };

    /// The box of half-widths `half` (along u, along v) around `center`.
    #[inline]
    pub fn around(center: Vec2, half: Vec2) -> Rect {
        Rect {
            u_min: center.x - half.x,
            u_max: center.x + half.x,
            v_min: center.y - half.y,
            v_max: center.y + half.y,
        }
    }

    /// True when the rectangle holds no point (an inverted bound, as [`Rect::EMPTY`]).
    pub fn is_empty(&self) -> bool {
        self.u_min > self.u_max || self.v_min > self.v_max
    }

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

    /// True when the two closed rectangles share a point, their boundaries included (two
    /// rectangles meeting along an edge touch but do not [`overlap`](Self::overlaps)).
    #[inline]
    pub fn touches(&self, other: &Rect) -> bool {
        self.u_max >= other.u_min
            && self.u_min <= other.u_max
            && self.v_max >= other.v_min
            && self.v_min <= other.v_max
    }

    /// The smallest rectangle holding both.
    #[inline]
    pub fn union(&self, other: &Rect) -> Rect {
        Rect {
            u_min: self.u_min.min(other.u_min),
            u_max: self.u_max.max(other.u_max),
            v_min: self.v_min.min(other.v_min),
            v_max: self.v_max.max(other.v_max),
        }
    }

    /// The rectangle grown by `margin` on every side.
    pub fn grow(&self, margin: f32) -> Rect {
        Rect {
            u_min: self.u_min - margin,
            u_max: self.u_max + margin,
            v_min: self.v_min - margin,
            v_max: self.v_max + margin,
        }
    }

    /// The rectangle clamped into `bounds` (which must not be empty): each lower edge into
    /// `bounds`, each upper edge between the clamped lower edge and the bound, so the result
    /// is never inverted.
    pub fn clamp_to(&self, bounds: &Rect) -> Rect {
        let u_min = self.u_min.clamp(bounds.u_min, bounds.u_max);
        let v_min = self.v_min.clamp(bounds.v_min, bounds.v_max);
        Rect {
            u_min,
            u_max: self.u_max.clamp(u_min, bounds.u_max),
            v_min,
            v_max: self.v_max.clamp(v_min, bounds.v_max),
        }
    }

    /// The region where this rectangle and `other`, differing in at most one edge, differ:
    /// the strip between the two positions of that edge, across the extent of both ([`EMPTY`]
    /// when they are the same). `None` when they differ in more than one edge.
    ///
    /// [`EMPTY`]: Rect::EMPTY
    pub fn changed_strip(&self, other: &Rect) -> Option<Rect> {
        let (a, b) = (self, other);
        let du = (a.u_min != b.u_min, a.u_max != b.u_max);
        let dv = (a.v_min != b.v_min, a.v_max != b.v_max);
        let changed = [du.0, du.1, dv.0, dv.1].iter().filter(|&&d| d).count();
        match changed {
            0 => Some(Rect::EMPTY),
            1 => {
                let (lo_u, hi_u) = (a.u_min.min(b.u_min), a.u_max.max(b.u_max));
                let (lo_v, hi_v) = (a.v_min.min(b.v_min), a.v_max.max(b.v_max));
                Some(if du.0 {
                    Rect {
                        u_min: lo_u,
                        u_max: a.u_min.max(b.u_min),
                        v_min: lo_v,
                        v_max: hi_v,
                    }
                } else if du.1 {
                    Rect {
                        u_min: a.u_max.min(b.u_max),
                        u_max: hi_u,
                        v_min: lo_v,
                        v_max: hi_v,
                    }
                } else if dv.0 {
                    Rect {
                        u_min: lo_u,
                        u_max: hi_u,
                        v_min: lo_v,
                        v_max: a.v_min.max(b.v_min),
                    }
                } else {
                    Rect {
                        u_min: lo_u,
                        u_max: hi_u,
                        v_min: a.v_max.min(b.v_max),
                        v_max: hi_v,
                    }
                })
            }
            _ => None,
        }
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

#[cfg(test)]
mod tests {
    use super::*;

    fn r(u_min: f32, u_max: f32, v_min: f32, v_max: f32) -> Rect {
        Rect {
            u_min,
            u_max,
            v_min,
            v_max,
        }
    }

    #[test]
    fn the_empty_rectangle_is_empty_and_the_identity_of_union() {
        assert!(Rect::EMPTY.is_empty());
        assert!(r(1.0, 0.0, 0.0, 1.0).is_empty());
        assert!(r(0.0, 1.0, 2.0, 1.0).is_empty());
        assert!(!r(0.0, 0.0, 0.0, 0.0).is_empty(), "a point is not empty");
        let a = r(-1.0, 2.0, 0.5, 3.0);
        assert_eq!(Rect::EMPTY.union(&a), a);
        assert_eq!(a.union(&Rect::EMPTY), a);
        assert!(!Rect::EMPTY.touches(&a) && !a.touches(&Rect::EMPTY));
        assert!(!Rect::EMPTY.contains(Vec2::ZERO));
    }

    #[test]
    fn union_around_and_grow_give_hand_computed_boxes() {
        let a = r(0.0, 1.0, 0.0, 1.0);
        let b = r(0.5, 3.0, -2.0, 0.25);
        assert_eq!(a.union(&b), r(0.0, 3.0, -2.0, 1.0));
        assert_eq!(
            Rect::around(Vec2::new(1.0, -2.0), Vec2::new(0.5, 0.25)),
            r(0.5, 1.5, -2.25, -1.75)
        );
        assert_eq!(a.grow(0.5), r(-0.5, 1.5, -0.5, 1.5));
        assert_eq!(a.grow(0.0), a);
    }

    #[test]
    fn clamp_to_keeps_the_rectangle_inside_and_never_inverted() {
        let bounds = r(0.0, 10.0, -1.0, 1.0);
        // Inside: unchanged.
        assert_eq!(
            r(1.0, 2.0, 0.0, 0.5).clamp_to(&bounds),
            r(1.0, 2.0, 0.0, 0.5)
        );
        // Sticking out on every side: cut to the bounds.
        assert_eq!(
            r(-5.0, 20.0, -3.0, 3.0).clamp_to(&bounds),
            r(0.0, 10.0, -1.0, 1.0)
        );
        // Wholly beyond the upper bounds: squeezed onto them.
        assert_eq!(
            r(12.0, 15.0, 2.0, 4.0).clamp_to(&bounds),
            r(10.0, 10.0, 1.0, 1.0)
        );
        // Wholly below: the upper edges clamp to the clamped lower ones.
        assert_eq!(
            r(-9.0, -8.0, -5.0, -4.0).clamp_to(&bounds),
            r(0.0, 0.0, -1.0, -1.0)
        );
    }

    #[test]
    fn touches_counts_shared_boundaries_and_overlaps_does_not() {
        let a = r(0.0, 1.0, 0.0, 1.0);
        // Sharing the edge u = 1.
        let side = r(1.0, 2.0, 0.0, 1.0);
        assert!(a.touches(&side) && side.touches(&a));
        assert!(!a.overlaps(&side));
        // Sharing the corner (1, 1) only.
        assert!(a.touches(&r(1.0, 2.0, 1.0, 2.0)));
        // Apart along v.
        assert!(!a.touches(&r(0.0, 1.0, 1.5, 2.0)));
        // Inside.
        let inner = r(0.25, 0.5, 0.25, 0.5);
        assert!(a.touches(&inner) && a.overlaps(&inner));
    }

    #[test]
    fn changed_strip_is_the_swept_region_of_one_edge() {
        let a = r(0.0, 2.0, 0.0, 1.0);
        assert_eq!(a.changed_strip(&a), Some(Rect::EMPTY));
        // Left edge from 0 to 0.5: the strip between them, the full height.
        assert_eq!(
            a.changed_strip(&r(0.5, 2.0, 0.0, 1.0)),
            Some(r(0.0, 0.5, 0.0, 1.0))
        );
        // Right edge out from 2 to 3, either order.
        let wider = r(0.0, 3.0, 0.0, 1.0);
        assert_eq!(a.changed_strip(&wider), Some(r(2.0, 3.0, 0.0, 1.0)));
        assert_eq!(wider.changed_strip(&a), Some(r(2.0, 3.0, 0.0, 1.0)));
        // Bottom edge down to -1; top edge in to 0.75.
        assert_eq!(
            a.changed_strip(&r(0.0, 2.0, -1.0, 1.0)),
            Some(r(0.0, 2.0, -1.0, 0.0))
        );
        assert_eq!(
            a.changed_strip(&r(0.0, 2.0, 0.0, 0.75)),
            Some(r(0.0, 2.0, 0.75, 1.0))
        );
        // Two edges: no strip.
        assert_eq!(a.changed_strip(&r(0.5, 2.5, 0.0, 1.0)), None);
    }
}
