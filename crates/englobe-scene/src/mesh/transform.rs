//! Moving a mesh into the scene: positions by the affine transform, normals by the inverse
//! transpose of its linear part (so they stay perpendicular to the surface under non-uniform
//! scales and shears), tangents by the linear part itself, their handedness flipped by a mirror.

use englobe::{Affine3A, TriangleMesh};
use glam::Vec4;

/// Tangents (see [`crate::SceneObject::tangents`]) moved by `m`'s linear part.
pub fn transform_tangents(tangents: &[Vec4], m: &Affine3A) -> Vec<Vec4> {
    let flip = if m.matrix3.determinant() < 0.0 { -1.0 } else { 1.0 };
    tangents
        .iter()
        .map(|t| (m.matrix3 * t.truncate()).normalize_or_zero().extend(if t.w < 0.0 { -flip } else { flip }))
        .collect()
}

/// The mesh with `m` applied to its vertices and normals (texture coordinates copied as they
/// are). Refuses transforms that are singular or that carry a vertex beyond what `f32` holds.
pub fn bake_transform(mesh: &TriangleMesh, m: &Affine3A) -> Result<TriangleMesh, String> {
    let det = m.matrix3.determinant();
    let inverse = m.inverse();
    if !m.is_finite() || det == 0.0 || !inverse.is_finite() {
        return Err(format!("the transform is singular or not finite (determinant {det})"));
    }
    let positions: Vec<_> = mesh.positions().iter().map(|&p| m.transform_point3(p)).collect();
    if let Some(p) = positions.iter().find(|p| !p.is_finite()) {
        return Err(format!("the transform carries a vertex beyond the range of 32-bit floats ({p})"));
    }
    let mut out = TriangleMesh::new(positions, mesh.triangles().to_vec()).map_err(|e| e.to_string())?;
    if let Some(normals) = mesh.normals() {
        let to_world = inverse.matrix3.transpose();
        out = out
            .with_normals(normals.iter().map(|&n| (to_world * n).normalize_or_zero()).collect())
            .map_err(|e| e.to_string())?;
    }
    if let Some(uvs) = mesh.uvs() {
        out = out.with_uvs(uvs.to_vec()).map_err(|e| e.to_string())?;
    }
    if let Some(uvs) = mesh.uvs1() {
        out = out.with_uvs1(uvs.to_vec()).map_err(|e| e.to_string())?;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use englobe::Vec3;

    use super::*;

    #[test]
    fn positions_and_normals_follow() {
        let mesh = TriangleMesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]])
            .unwrap()
            .with_normals(vec![Vec3::Z; 3])
            .unwrap();
        let m = Affine3A::from_scale_rotation_translation(
            Vec3::new(2.0, 1.0, 1.0),
            glam::Quat::from_rotation_x(std::f32::consts::FRAC_PI_2),
            Vec3::new(1.0, 0.0, 0.0),
        );
        let out = bake_transform(&mesh, &m).unwrap();
        assert!((out.positions()[1] - Vec3::new(3.0, 0.0, 0.0)).length() < 1e-6);
        assert!((out.normals().unwrap()[0] - Vec3::new(0.0, -1.0, 0.0)).length() < 1e-6);
        assert!(bake_transform(&mesh, &Affine3A::from_scale(Vec3::ZERO)).is_err());
        let far = Affine3A::from_scale_rotation_translation(Vec3::splat(3e38), glam::Quat::IDENTITY, Vec3::splat(3e38));
        assert!(bake_transform(&mesh, &far).is_err());
    }

    #[test]
    fn tangents_follow_and_mirrors_flip_them() {
        let t = [Vec4::new(1.0, 0.0, 0.0, 1.0), Vec4::new(0.0, 1.0, 0.0, -1.0)];
        let turn = Affine3A::from_rotation_z(std::f32::consts::FRAC_PI_2);
        let out = transform_tangents(&t, &turn);
        assert!((out[0] - Vec4::new(0.0, 1.0, 0.0, 1.0)).length() < 1e-6);
        assert!((out[1] - Vec4::new(-1.0, 0.0, 0.0, -1.0)).length() < 1e-6);
        let mirror = Affine3A::from_scale(Vec3::new(-2.0, 1.0, 1.0));
        let out = transform_tangents(&t, &mirror);
        assert_eq!(out, [Vec4::new(-1.0, 0.0, 0.0, -1.0), Vec4::new(0.0, 1.0, 0.0, 1.0)]);
    }
}
