//! Numbers that are checked while the file is read, so that a bad value is reported at its own
//! line and column: every number must be finite and fit `f32`, and some must be positive or lie
//! in `0..=1`.

use englobe::{Affine3A, Mat4, Vec3};
use serde::de::Error;
use serde::{Deserialize, Deserializer};

fn finite_f32<'de, D: Deserializer<'de>>(d: D) -> Result<f32, D::Error> {
    let v = f64::deserialize(d)?;
    if !v.is_finite() {
        return Err(D::Error::custom(format!("expected a finite number, found {v}")));
    }
    if v.abs() > f32::MAX as f64 {
        return Err(D::Error::custom(format!(
            "{v} is too large: numbers must fit a 32-bit float (at most about 3.4e38)"
        )));
    }
    Ok(v as f32)
}

/// A finite number.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Finite(pub f32);

impl<'de> Deserialize<'de> for Finite {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        finite_f32(d).map(Finite)
    }
}

/// A finite number greater than zero.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Positive(pub f32);

impl<'de> Deserialize<'de> for Positive {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let v = finite_f32(d)?;
        if v > 0.0 {
            Ok(Positive(v))
        } else {
            Err(D::Error::custom(format!("expected a number greater than 0, found {v}")))
        }
    }
}

/// A finite number zero or greater.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NonNegative(pub f32);

impl<'de> Deserialize<'de> for NonNegative {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let v = finite_f32(d)?;
        if v >= 0.0 {
            Ok(NonNegative(v))
        } else {
            Err(D::Error::custom(format!("expected a number of at least 0, found {v}")))
        }
    }
}

/// A number in `0..=1`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fraction(pub f32);

impl<'de> Deserialize<'de> for Fraction {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let v = finite_f32(d)?;
        if (0.0..=1.0).contains(&v) {
            Ok(Fraction(v))
        } else {
            Err(D::Error::custom(format!("expected a number between 0 and 1, found {v}")))
        }
    }
}

/// A point or direction: an array of three finite numbers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point(pub Vec3);

impl<'de> Deserialize<'de> for Point {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let [x, y, z] = <[Finite; 3]>::deserialize(d)?;
        Ok(Point(Vec3::new(x.0, y.0, z.0)))
    }
}

/// A colour: three numbers of at least 0 (linear RGB; values above 1 are allowed for lights).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Color(pub Vec3);

impl<'de> Deserialize<'de> for Color {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let [r, g, b] = <[NonNegative; 3]>::deserialize(d)?;
        Ok(Color(Vec3::new(r.0, g.0, b.0)))
    }
}

/// A scale: one number for all axes or three, none of them zero (a zero scale flattens the mesh
/// and cannot be undone when rays are moved into its space).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scale(pub Vec3);

impl<'de> Deserialize<'de> for Scale {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum Either {
            One(f64),
            Three([f64; 3]),
        }
        let v = match Either::deserialize(d).map_err(|_| D::Error::custom("expected a number or [x, y, z]"))? {
            Either::One(s) => [s; 3],
            Either::Three(v) => v,
        };
        let mut out = Vec3::ZERO;
        for (k, x) in v.into_iter().enumerate() {
            if !x.is_finite() || x.abs() > f32::MAX as f64 || x as f32 == 0.0 {
                return Err(D::Error::custom(format!("a scale must be finite and not zero, found {x}")));
            }
            out[k] = x as f32;
        }
        Ok(Scale(out))
    }
}

/// An affine 4x4 matrix written row by row: four rows of four finite numbers, the last row
/// `[0, 0, 0, 1]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Matrix(pub Affine3A);

impl<'de> Deserialize<'de> for Matrix {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let rows = <[[Finite; 4]; 4]>::deserialize(d)?;
        let last = rows[3].map(|x| x.0);
        if last != [0.0, 0.0, 0.0, 1.0] {
            return Err(D::Error::custom(format!(
                "the matrix's last row is {last:?}; an affine transform needs [0, 0, 0, 1]"
            )));
        }
        let m = Mat4::from_cols_array_2d(&rows.map(|r| r.map(|x| x.0))).transpose();
        Ok(Matrix(Affine3A::from_mat4(m)))
    }
}
