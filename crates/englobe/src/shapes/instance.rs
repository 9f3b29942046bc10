//! Instances: one triangle mesh placed in the world by an affine transform, so that the same mesh
//! can appear many times while its triangles and its bottom-level structure exist once.
//!
//! This is the two-level hierarchy of Wald, Benthin and Slusallek (2003), "A Simple and Practical
//! Method for Interactive Ray Tracing of Dynamic Scenes": instances sit in a top-level structure;
//! a ray that reaches one is moved into the mesh's own space and traced against the mesh's
//! bottom-level structure there. The direction is transformed but never renormalised, so the ray
//! parameter `t` means the same point in both spaces and hits from different instances compare
//! directly. Normals go back to the world with the inverse transpose of the linear part.

use std::sync::Arc;

use glam::{Affine3A, Mat3A, Vec3};

use super::TriangleMesh;
use crate::{Aabb, Ray};

/// Why an instance was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum InstanceError {
    /// The transform has NaN or infinite entries.
    #[error("the instance transform has non-finite entries")]
    NonFinite,
    /// The transform cannot be inverted (a zero scale, or axes on one plane), so rays cannot be
    /// moved into the mesh's space.
    #[error("the instance transform is singular (determinant {0}); a scale of zero is not allowed")]
    Singular(f32),
    /// The mesh has no triangle: there is nothing to place.
    #[error("the instanced mesh has no triangle")]
    EmptyMesh,
}

/// A mesh placed by an affine transform. Cloning shares the mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct Instance {
    mesh: Arc<TriangleMesh>,
    to_world: Affine3A,
    to_local: Affine3A,
    normal_to_world: Mat3A,
    bounds: Aabb,
}

impl Instance {
    /// The mesh `mesh` moved by `to_world` (mesh space to world space).
    ///
    /// ```
    /// use std::sync::Arc;
    /// use englobe::{AccelKind, Affine3A, Instance, NoCount, Ray, TriangleMesh, Vec3, World};
    ///
    /// let tri = Arc::new(TriangleMesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]])?);
    /// // The same triangle twice, 5 and 10 units away: one mesh, two transforms.
    /// let objects = [5.0, 10.0]
    ///     .map(|z| Instance::new(tri.clone(), Affine3A::from_translation(Vec3::new(0.0, 0.0, z))).unwrap().into());
    /// let world = World::build(objects.to_vec(), AccelKind::None)?;
    /// let hit = world.closest_hit(&Ray::new(Vec3::new(0.2, 0.2, 0.0), Vec3::Z), &mut NoCount).unwrap();
    /// assert_eq!((hit.object, hit.prim), (0, 0));
    /// assert!((hit.t - 5.0).abs() < 1e-5);
    /// assert_eq!(world.bottom_levels().len(), 1);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn new(mesh: Arc<TriangleMesh>, to_world: Affine3A) -> Result<Self, InstanceError> {
        if mesh.is_empty() {
            return Err(InstanceError::EmptyMesh);
        }
        if !to_world.is_finite() {
            return Err(InstanceError::NonFinite);
        }
        let det = to_world.matrix3.determinant();
        let to_local = to_world.inverse();
        if det == 0.0 || !to_local.is_finite() {
            return Err(InstanceError::Singular(det));
        }
        let normal_to_world = to_local.matrix3.transpose();
        let bounds = transform_box(&mesh.bounds(), &to_world);
        if !bounds.is_finite() {
            return Err(InstanceError::NonFinite);
        }
        Ok(Instance { mesh, to_world, to_local, normal_to_world, bounds })
    }

    /// The mesh, in its own space.
    pub fn mesh(&self) -> &Arc<TriangleMesh> {
        &self.mesh
    }

    /// Mesh space to world space.
    pub fn to_world(&self) -> &Affine3A {
        &self.to_world
    }

    /// World space to mesh space.
    pub fn to_local(&self) -> &Affine3A {
        &self.to_local
    }

    /// The box around the placed mesh, in world space (the transformed corners of the mesh's box).
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// The ray in mesh space: same interval, direction transformed but not renormalised, so a hit
    /// at `t` there is the hit at `t` in the world.
    #[inline(always)]
    pub fn local_ray(&self, ray: &Ray) -> Ray {
        Ray::segment(
            self.to_local.transform_point3(ray.origin()),
            self.to_local.transform_vector3(ray.dir()),
            ray.t_min,
            ray.t_max,
        )
    }

    /// A mesh-space normal moved to the world (inverse transpose) and normalised; zero stays zero.
    #[inline]
    pub fn normal_to_world(&self, n: Vec3) -> Vec3 {
        (self.normal_to_world * n).normalize_or_zero()
    }
}

/// The box around the eight transformed corners of `b`.
pub fn transform_box(b: &Aabb, m: &Affine3A) -> Aabb {
    if b.is_empty() {
        return Aabb::EMPTY;
    }
    Aabb::from_points((0..8).map(|i| {
        let corner = Vec3::new(
            if i & 1 == 0 { b.min.x } else { b.max.x },
            if i & 2 == 0 { b.min.y } else { b.max.y },
            if i & 4 == 0 { b.min.z } else { b.max.z },
        );
        m.transform_point3(corner)
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> Arc<TriangleMesh> {
        Arc::new(
            TriangleMesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y], vec![[0, 1, 2], [0, 2, 3]])
                .unwrap(),
        )
    }

    #[test]
    fn singular_and_non_finite_transforms_are_refused() {
        let e = Instance::new(square(), Affine3A::from_scale(Vec3::new(1.0, 0.0, 1.0))).unwrap_err();
        assert!(matches!(e, InstanceError::Singular(_)), "{e}");
        let e = Instance::new(square(), Affine3A::from_translation(Vec3::new(f32::NAN, 0.0, 0.0))).unwrap_err();
        assert_eq!(e, InstanceError::NonFinite);
        let empty = Arc::new(TriangleMesh::new(vec![], vec![]).unwrap());
        assert_eq!(Instance::new(empty, Affine3A::IDENTITY).unwrap_err(), InstanceError::EmptyMesh);
    }

    #[test]
    fn the_local_ray_keeps_t() {
        let to_world = Affine3A::from_scale_rotation_translation(
            Vec3::splat(3.0),
            glam::Quat::from_rotation_y(0.7),
            Vec3::new(10.0, -2.0, 5.0),
        );
        let inst = Instance::new(square(), to_world).unwrap();
        let ray = Ray::new(Vec3::new(1.0, 2.0, 3.0), Vec3::new(0.3, -0.2, 1.0));
        let local = inst.local_ray(&ray);
        for t in [0.0f32, 1.0, 7.5] {
            let back = to_world.transform_point3(local.at(t));
            assert!((back - ray.at(t)).length() < 1e-4, "t = {t}: {back} vs {}", ray.at(t));
        }
    }

    #[test]
    fn bounds_and_normals_follow_the_transform() {
        let to_world = Affine3A::from_scale_rotation_translation(
            Vec3::new(2.0, 1.0, 1.0),
            glam::Quat::from_rotation_x(std::f32::consts::FRAC_PI_2),
            Vec3::new(0.0, 0.0, 4.0),
        );
        let inst = Instance::new(square(), to_world).unwrap();
        let b = inst.bounds();
        assert!((b.min - Vec3::new(0.0, 0.0, 4.0)).length() < 1e-6, "{b:?}");
        assert!((b.max - Vec3::new(2.0, 0.0, 5.0)).length() < 1e-6, "{b:?}");
        // The square's normal +z turns to -y under a quarter turn about x.
        let n = inst.normal_to_world(Vec3::Z);
        assert!((n - Vec3::new(0.0, -1.0, 0.0)).length() < 1e-6, "{n}");
    }

    #[test]
    fn normals_use_the_inverse_transpose() {
        // A shear: the transformed normal must stay perpendicular to transformed tangents.
        let shear = Affine3A::from_mat3(glam::Mat3::from_cols(Vec3::X, Vec3::new(0.8, 1.0, 0.0), Vec3::Z));
        let inst = Instance::new(square(), shear).unwrap();
        let n = Vec3::new(0.0, 1.0, 1.0).normalize();
        let world_n = inst.normal_to_world(n);
        for tangent in [Vec3::X, Vec3::new(0.0, 1.0, -1.0)] {
            let t = shear.transform_vector3(tangent);
            assert!(world_n.dot(t).abs() < 1e-6);
        }
    }
}
