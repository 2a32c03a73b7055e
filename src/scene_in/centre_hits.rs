//! The first hits of the camera rays through pixel centres, kept per box of pixels.
//!
//! A fit looks for each lamp's direct image (`fitting::joint::direct_images`) several times:
//! to place the start lights on the images, to give each lamp a light of its own, and to
//! bound each light's region of interest; a statistical fit after an exact one does it all
//! again. Each look reads the centre rays' hits of the pixels it tests in a box around the
//! light (its bright pixels and their neighbours; every pixel where that is not enough), and
//! the boxes mostly repeat or nest (on Table 1 the second and third boxes lie inside the
//! first). The hits depend only on the scene's triangles, the camera and the image size, so
//! a box traced once serves every later box inside it whose pixels it traced, hit for hit:
//! the results are the same to the last bit. The pixels a box leaves out are marked so, and
//! a later box that needs one of them is traced again.
//! The water mask (`crate::water_mask`) traces the whole image this way first when it holds
//! at most [`KEPT_PIXELS`], so every later box is read from its hits.
//!
//! The boxes are kept with their key (the tracer's identity, the camera, the image size), so
//! a scene whose tracer is rebuilt or whose camera is moved never reads a stale hit, and up
//! to [`KEPT_PIXELS`] pixels in all (64 MiB), the oldest box dropped first.

use std::sync::{Arc, Mutex};

use rayon::prelude::*;

use super::Scene;
use crate::tracing::PACKET_RAYS;

/// The most pixels the kept boxes hold together (8 bytes each).
pub const KEPT_PIXELS: usize = 8 << 20;

/// A pixel's entry: the triangle first hit (or one of the two markers) and the distance.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Entry {
    triangle: u32,
    t: f32,
}

/// The ray met nothing.
const MISS: u32 = u32::MAX;
/// The pixel was not asked for when the box was traced.
const SKIPPED: u32 = u32::MAX - 1;

/// A box of pixels, inclusive: `(x0, y0, x1, y1)`.
pub type PixelBox = (u32, u32, u32, u32);

/// What a box's hits depend on besides the pixels: the tracer, the camera and the image size.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Key {
    tracer: u64,
    camera: [u32; 14],
    size: (u32, u32),
}

/// A traced box.
struct Traced {
    key: Key,
    area: PixelBox,
    hits: Arc<Vec<Entry>>,
}

/// The boxes traced so far (module doc).
#[derive(Default)]
pub(super) struct CentreHitCache {
    boxes: Mutex<Vec<Traced>>,
}

/// The centre hits of a box of pixels ([`Scene::centre_hits`]).
pub struct BoxHits {
    area: PixelBox,
    hits: Arc<Vec<Entry>>,
}

impl BoxHits {
    /// The first hit of pixel `(x, y)`'s centre ray: the triangle's index in
    /// [`Scene::triangles`] and the distance, or `None` when it meets nothing. `None` too for
    /// a pixel outside the box, and for one `skip` left out unless a box traced before held
    /// its hit.
    pub fn get(&self, x: u32, y: u32) -> Option<(u32, f32)> {
        let (x0, y0, x1, y1) = self.area;
        if x < x0 || x > x1 || y < y0 || y > y1 {
            return None;
        }
        let e = self.hits[((y - y0) * (x1 - x0 + 1) + (x - x0)) as usize];
        (e.triangle != MISS && e.triangle != SKIPPED).then_some((e.triangle, e.t))
    }
}

fn contains(outer: PixelBox, inner: PixelBox) -> bool {
    outer.0 <= inner.0 && outer.1 <= inner.1 && outer.2 >= inner.2 && outer.3 >= inner.3
}

fn pixels(area: PixelBox) -> usize {
    (area.2 - area.0 + 1) as usize * (area.3 - area.1 + 1) as usize
}

impl Scene {
    fn centre_key(&self, width: u32, height: u32) -> Key {
        let c = &self.camera;
        let v = |v: glam::Vec3| [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()];
        let [p, r, u, f] = [v(c.position), v(c.right), v(c.up), v(c.forward)];
        Key {
            tracer: self.tracer.id(),
            camera: [
                p[0],
                p[1],
                p[2],
                r[0],
                r[1],
                r[2],
                u[0],
                u[1],
                u[2],
                f[0],
                f[1],
                f[2],
                c.yfov.to_bits(),
                c.aspect_for(width, height).to_bits(),
            ],
            size: (width, height),
        }
    }

    /// The direction of the camera ray through the centre of pixel (`x`, `y`).
    fn centre_direction(&self, x: u32, y: u32, width: u32, height: u32) -> glam::Vec3 {
        self.camera
            .direction(x as f32 + 0.5, y as f32 + 0.5, width, height)
    }

    /// The first hits of the camera rays through the centres of pixels `x0..=x1` of row `y`
    /// of a `width` x `height` image, traced in packets of neighbours (which run close
    /// together), given to `each` in order: `None` for a pixel `skip` leaves out, else the
    /// first hit of `Scene::tracer` (the triangle and the distance, `None` for a miss), as a
    /// single ray gets it, to the bit.
    pub fn centre_row(
        &self,
        y: u32,
        (x0, x1): (u32, u32),
        width: u32,
        height: u32,
        skip: &dyn Fn(u32) -> bool,
        each: &mut dyn FnMut(Option<Option<(u32, f32)>>),
    ) {
        let mut dirs = Vec::with_capacity(PACKET_RAYS);
        let mut xs = Vec::with_capacity(PACKET_RAYS);
        let mut found = [None; PACKET_RAYS];
        let unlimited = [f32::INFINITY; PACKET_RAYS];
        for first in (x0..=x1).step_by(PACKET_RAYS) {
            let last = (first + PACKET_RAYS as u32 - 1).min(x1);
            dirs.clear();
            xs.clear();
            for x in first..=last {
                if !skip(x) {
                    dirs.push(self.centre_direction(x, y, width, height));
                    xs.push(x);
                }
            }
            let found = &mut found[..dirs.len()];
            self.tracer.closest_hits(
                self.camera.position,
                &dirs,
                0.0,
                &unlimited[..dirs.len()],
                found,
            );
            let mut traced = xs.iter().zip(found.iter());
            let mut next = traced.next();
            for x in first..=last {
                match next {
                    Some((&tx, hit)) if tx == x => {
                        next = traced.next();
                        each(Some(hit.map(|h| (h.triangle, h.t))));
                    }
                    _ => each(None),
                }
            }
        }
    }

    /// The first hit (`Scene::tracer`) of the camera ray through the centre of every pixel
    /// of `area` (inclusive, inside a `width` x `height` image) but those `skip` (by row-major
    /// pixel index) leaves out, from a box traced before when one holds them all (module
    /// doc).
    pub fn centre_hits(
        &self,
        area: PixelBox,
        width: u32,
        height: u32,
        skip: &(dyn Fn(usize) -> bool + Sync),
    ) -> BoxHits {
        let key = self.centre_key(width, height);
        let (x0, y0, x1, y1) = area;
        let index = |x: u32, y: u32| y as usize * width as usize + x as usize;
        let kept = self.centre_hit_cache.boxes.lock().ok().and_then(|boxes| {
            boxes
                .iter()
                .rev()
                .find(|b| b.key == key && contains(b.area, area))
                .map(|b| BoxHits {
                    area: b.area,
                    hits: Arc::clone(&b.hits),
                })
        });
        if let Some(kept) = kept {
            let (kx0, ky0, kx1, _) = kept.area;
            let complete = (y0..=y1).into_par_iter().all(|y| {
                (x0..=x1).all(|x| {
                    skip(index(x, y))
                        || kept.hits[((y - ky0) * (kx1 - kx0 + 1) + (x - kx0)) as usize].triangle
                            != SKIPPED
                })
            });
            if complete {
                return kept;
            }
        }
        let hits: Vec<Entry> = (y0..y1 + 1)
            .into_par_iter()
            // A few rows a task: the rows that see the water cost many times those that
            // see the sky, and a long last task would leave the other cores idle.
            .with_max_len(2)
            .flat_map_iter(|y| {
                let mut row = Vec::with_capacity((x1 - x0 + 1) as usize);
                self.centre_row(
                    y,
                    (x0, x1),
                    width,
                    height,
                    &|x| skip(index(x, y)),
                    &mut |hit| {
                        row.push(match hit {
                            None => Entry {
                                triangle: SKIPPED,
                                t: 0.0,
                            },
                            Some(None) => Entry {
                                triangle: MISS,
                                t: 0.0,
                            },
                            Some(Some((triangle, t))) => Entry { triangle, t },
                        })
                    },
                );
                row
            })
            .collect();
        let hits = Arc::new(hits);
        if let Ok(mut boxes) = self.centre_hit_cache.boxes.lock() {
            // A box the new one holds is of no more use (short of pixels the new one
            // skipped, which a later look traces again).
            boxes.retain(|b| !(b.key == key && contains(area, b.area)));
            boxes.push(Traced {
                key,
                area,
                hits: Arc::clone(&hits),
            });
            while boxes.len() > 1
                && boxes.iter().map(|b| pixels(b.area)).sum::<usize>() > KEPT_PIXELS
            {
                boxes.remove(0);
            }
            if pixels(area) > KEPT_PIXELS {
                boxes.clear();
            }
        }
        BoxHits { area, hits }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn boxes_contain_and_count() {
        assert!(contains((0, 0, 9, 9), (2, 3, 9, 4)));
        assert!(!contains((1, 0, 9, 9), (0, 3, 4, 4)));
        assert_eq!(pixels((2, 3, 4, 4)), 6);
    }

    /// Every pixel of `area` but those `skip` leaves out has the hit the tracer gives its
    /// centre ray, to the bit; those left out have none.
    fn assert_traced(
        scene: &Scene,
        got: &BoxHits,
        area: PixelBox,
        size: u32,
        skip: &dyn Fn(usize) -> bool,
    ) {
        let origin = scene.camera.position;
        for y in area.1..=area.3 {
            for x in area.0..=area.2 {
                let want = if skip(y as usize * size as usize + x as usize) {
                    None
                } else {
                    let dir = scene
                        .camera
                        .direction(x as f32 + 0.5, y as f32 + 0.5, size, size);
                    scene
                        .tracer
                        .closest_hit(origin, dir, 0.0, f32::INFINITY)
                        .map(|h| (h.triangle, h.t.to_bits()))
                };
                assert_eq!(
                    got.get(x, y).map(|(k, t)| (k, t.to_bits())),
                    want,
                    "({x}, {y})"
                );
            }
        }
    }

    /// A box inside one traced before reads that one's hits; a pixel the first left out is
    /// traced when a later box asks for it; a moved camera or a rebuilt tracer is never
    /// served the old hits. Each answer is checked against the tracer itself.
    #[test]
    fn kept_boxes_serve_only_what_they_hold() {
        let crate::samples::Fixture {
            mut scene,
            photo,
            water,
            ..
        } = crate::samples::load_fixture("table1.png");
        let size = photo.width;
        assert_eq!(photo.height, size);
        // The fixture's water mask traced the whole image: start with nothing kept.
        scene.centre_hit_cache = CentreHitCache::default();
        let water_skip = |i: usize| water[i];
        // A box across the wall, the light and the horizon: the water pixels left out.
        let outer = (200, 150, 420, 360);
        let first = scene.centre_hits(outer, size, size, &water_skip);
        assert_traced(&scene, &first, outer, size, &water_skip);
        assert!(
            water[360 * size as usize + 300],
            "the box reaches the water"
        );
        let inner = (250, 200, 400, 340);
        let again = scene.centre_hits(inner, size, size, &water_skip);
        assert!(
            Arc::ptr_eq(&first.hits, &again.hits),
            "the kept box serves the one inside it"
        );
        assert_traced(&scene, &again, inner, size, &water_skip);
        // Nothing left out now: the water pixels must be traced, not read as missing.
        let none = |_: usize| false;
        let all = scene.centre_hits(inner, size, size, &none);
        assert!(!Arc::ptr_eq(&first.hits, &all.hits));
        assert_traced(&scene, &all, inner, size, &none);
        // The camera moved up 1 m: every hit changes, none is read from before.
        scene.camera.position.y += 1.0;
        let moved = scene.centre_hits(inner, size, size, &none);
        assert!(!Arc::ptr_eq(&all.hits, &moved.hits));
        assert_traced(&scene, &moved, inner, size, &none);
        // A rebuilt tracer (here without the wall) is a new key too.
        let dry: Vec<crate::tracing::Triangle> = scene
            .triangles
            .iter()
            .zip(&scene.is_water)
            .filter(|(_, &w)| w)
            .map(|(&vertices, _)| crate::tracing::Triangle { vertices })
            .collect();
        scene.tracer = crate::tracing::Tracer::new(&dry);
        let rebuilt = scene.centre_hits(inner, size, size, &none);
        assert!(!Arc::ptr_eq(&moved.hits, &rebuilt.hits));
        assert_traced(&scene, &rebuilt, inner, size, &none);
        // The whole image, as the water mask traces it, serves every box after it, with the
        // hits of the pixels a later box leaves out.
        let whole = scene.centre_hits((0, 0, size - 1, size - 1), size, size, &none);
        let later = scene.centre_hits(outer, size, size, &water_skip);
        assert!(Arc::ptr_eq(&whole.hits, &later.hits));
        assert_traced(&scene, &later, outer, size, &none);
    }
}
