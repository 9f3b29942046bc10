//! What a world is made of: [`Object`], a shape, a mesh or an instance of a mesh.

use std::sync::Arc;

use crate::shapes::{Instance, Shape, TriangleMesh};

/// One object of a world.
#[derive(Clone, Debug, PartialEq)]
pub enum Object {
    /// A single shape.
    Shape(Shape),
    /// A triangle mesh: each triangle is a primitive of its own.
    Mesh(Arc<TriangleMesh>),
    /// A mesh placed by a transform: one primitive of the world's structure, traced through a
    /// bottom-level structure over the mesh that all instances of the same mesh share.
    Instance(Instance),
}

impl<S: Into<Shape>> From<S> for Object {
    fn from(s: S) -> Self {
        Object::Shape(s.into())
    }
}

impl From<TriangleMesh> for Object {
    fn from(m: TriangleMesh) -> Self {
        Object::Mesh(Arc::new(m))
    }
}

impl From<Instance> for Object {
    fn from(i: Instance) -> Self {
        Object::Instance(i)
    }
}

impl Object {
    /// Number of primitives the object contributes to the world's structure.
    pub fn primitive_count(&self) -> usize {
        match self {
            Object::Shape(_) | Object::Instance(_) => 1,
            Object::Mesh(m) => m.len(),
        }
    }

    /// Number of triangles the object puts in the picture (an instance counts its mesh's).
    pub fn triangle_count(&self) -> usize {
        match self {
            Object::Shape(Shape::Triangle(_)) => 1,
            Object::Shape(_) => 0,
            Object::Mesh(m) => m.len(),
            Object::Instance(i) => i.mesh().len(),
        }
    }
}
