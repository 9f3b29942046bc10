//! Point and box queries of a [`World`]'s plain meshes: the closest point of their triangles to a
//! point, and the triangles that overlap a box, answered in terms of objects.
//!
//! On the fast path ([`crate::AccelKind::BvhWide`]) the plain meshes' triangles are in one
//! [`crate::TriangleBvh`], which answers both queries ([`crate::accel::wide::point_query`],
//! [`crate::accel::wide::box_query`]). The teaching structures hold boxes only, so for them the
//! queries test every triangle: the same answers, in linear time. Shapes and instances are not
//! part of these queries (an instance's transform need not preserve distances).

use glam::Vec3;

use super::{Object, World, WorldPoint};
use crate::Aabb;
use crate::shapes::{closest_point_on_triangle, distance_squared, is_degenerate, triangle_overlaps_box};

impl World {
    /// Every triangle of the plain meshes that can be hit (zero-area ones never are), as
    /// `(object, triangle, vertices)`, in primitive order.
    fn mesh_triangles(&self) -> impl Iterator<Item = (u32, u32, [Vec3; 3])> + '_ {
        self.objects.iter().enumerate().flat_map(|(object, o)| {
            let mesh = match o {
                Object::Mesh(m) => Some(m),
                _ => None,
            };
            mesh.into_iter().flat_map(move |m| {
                (0..m.len() as u32).filter_map(move |t| {
                    let [a, b, c] = m.triangle(t).vertices;
                    (!is_degenerate(a, b, c)).then_some((object as u32, t, [a, b, c]))
                })
            })
        })
    }

    /// The point of the plain meshes' triangles closest to `p`, at most `radius` away
    /// (`f32::INFINITY` for no limit); ties go to the lower object, then the lower triangle.
    /// `None` if nothing is that close, or `p` is not finite, or `radius` is negative or NaN.
    /// See [`crate::TriangleBvh::closest_point`].
    ///
    /// ```
    /// use englobe::{AccelKind, TriangleMesh, Vec3, World};
    ///
    /// let floor = TriangleMesh::from_arrays(&[[-5.0, 0.0, -5.0], [5.0, 0.0, -5.0], [0.0, 0.0, 5.0]], &[[0, 1, 2]])?;
    /// let world = World::build(vec![floor.into()], AccelKind::BvhWide)?;
    /// let near = world.closest_point(Vec3::new(0.0, 2.0, 0.0), 10.0).expect("the floor");
    /// assert_eq!((near.object, near.prim, near.distance), (0, 0, 2.0));
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn closest_point(&self, p: Vec3, radius: f32) -> Option<WorldPoint> {
        if let Some(bvh) = &self.triangles {
            let c = bvh.closest_point(p, radius)?;
            let (object, prim) = self.locate(c.prim);
            return Some(WorldPoint { object, prim, point: c.point, distance: c.distance });
        }
        if !p.is_finite() || !(radius >= 0.0) {
            return None;
        }
        let mut best: Option<(f32, WorldPoint)> = None;
        let limit = radius * radius;
        for (object, prim, v) in self.mesh_triangles() {
            let q = closest_point_on_triangle(p, v);
            let d2 = distance_squared(p, q);
            if best.map_or(d2 <= limit, |(b, _)| d2 < b) {
                best = Some((d2, WorldPoint { object, prim, point: q, distance: d2.sqrt() }));
            }
        }
        best.map(|(_, w)| w)
    }

    /// The triangles of the plain meshes that overlap `query` (boundaries included), as
    /// `(object, triangle)` in increasing order. See [`crate::TriangleBvh::triangles_in_box`].
    pub fn triangles_in_box(&self, query: &Aabb) -> Vec<(u32, u32)> {
        if let Some(bvh) = &self.triangles {
            return bvh.triangles_in_box(query).into_iter().map(|t| self.locate(t)).collect();
        }
        self.mesh_triangles().filter(|(_, _, v)| triangle_overlaps_box(*v, query)).map(|(o, t, _)| (o, t)).collect()
    }
}
