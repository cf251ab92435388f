//! Mass properties of parry shapes (feature `parry`, or `parry-f64` for double precision).
//!
//! parry computes the volume integrals (ball, cuboid, capsule, cylinder, cone, convex hull,
//! compound, …); this module turns them into validated [`MassProperties`] given a [`Density`].
//! parry and tumble share glam 0.33, so vectors and quaternions pass without conversion.
//!
//! The backend, re-exported as [`parry`]: `parry3d` in the default build, `parry3d-f64` with
//! `parry-f64`. An `f64` build with only `parry` keeps the `f32` shapes of `parry3d` and widens
//! their mass properties exactly (the integrals themselves then carry `f32` round-off).

#[cfg(all(feature = "parry", not(feature = "parry-f64")))]
pub use parry3d as parry;
#[cfg(feature = "parry-f64")]
pub use parry3d_f64 as parry;

use glam::{DMat3, DQuat, DVec3};
use parry::shape::Shape;

use crate::error::InvalidInput;
use crate::mass::{Density, Mass, MassProperties};
use crate::math::{Narrow, Vec3, to_f64};

mod quickhull;
use quickhull::hull_triangles;

/// Mass properties of `shape` made of a uniform material of the given `density`.
///
/// The mass is `ρ V`, the centre of mass and principal frame are parry's, in shape coordinates.
/// A shape without volume (e.g. a flat triangle) yields [`InvalidInput::NonPositiveMass`].
pub fn mass_properties_of(
    shape: &dyn Shape,
    density: Density,
) -> Result<MassProperties, InvalidInput> {
    from_parry(&shape.mass_properties(parry_density(density)))
}

/// Converts parry's mass properties into tumble's, validating them.
///
/// parry stores inverse moments with `0` meaning "infinite inertia"; tumble stores moments with
/// `0` meaning "locked axis". Both describe an axis that torques cannot spin up, so a zero inverse
/// maps to a zero moment.
pub fn from_parry(
    props: &parry::mass_properties::MassProperties,
) -> Result<MassProperties, InvalidInput> {
    let mass = Mass::new(to_real(props.mass()))?;
    MassProperties::new(mass, to_real(props.principal_inertia()))?
        .with_principal_frame(to_real(props.principal_inertia_local_frame))?
        .with_center_of_mass(to_real(props.local_com))
}

/// parry's numbers in the engine's precision: the identity unless an `f64` engine reads `f32`
/// shapes, which widens exactly.
#[cfg(any(not(feature = "f64"), feature = "parry-f64"))]
#[inline]
fn to_real<T>(value: T) -> T {
    value
}

/// parry's numbers in the engine's precision: an `f64` engine reading `f32` shapes widens exactly.
#[cfg(all(feature = "f64", not(feature = "parry-f64")))]
#[inline]
fn to_real<T: WidenParry>(value: T) -> T::Wide {
    value.widen_parry()
}

/// The density handed to parry, in parry's precision.
#[cfg(any(not(feature = "f64"), feature = "parry-f64"))]
#[inline]
fn parry_density(density: Density) -> crate::math::Real {
    density.get()
}

/// The density handed to parry3d's `f32` shapes from an `f64` engine (one rounding).
#[cfg(all(feature = "f64", not(feature = "parry-f64")))]
#[inline]
fn parry_density(density: Density) -> f32 {
    density.get() as f32
}

/// parry3d's `f32` numbers widened exactly for an `f64` engine.
#[cfg(all(feature = "f64", not(feature = "parry-f64")))]
trait WidenParry {
    /// The `f64` counterpart.
    type Wide;
    /// `self` in `f64`, exactly.
    fn widen_parry(self) -> Self::Wide;
}

#[cfg(all(feature = "f64", not(feature = "parry-f64")))]
impl WidenParry for f32 {
    type Wide = f64;
    fn widen_parry(self) -> f64 {
        f64::from(self)
    }
}

#[cfg(all(feature = "f64", not(feature = "parry-f64")))]
impl WidenParry for glam::Vec3 {
    type Wide = glam::DVec3;
    fn widen_parry(self) -> glam::DVec3 {
        self.as_dvec3()
    }
}

#[cfg(all(feature = "f64", not(feature = "parry-f64")))]
impl WidenParry for glam::Quat {
    type Wide = glam::DQuat;
    fn widen_parry(self) -> glam::DQuat {
        self.as_dquat()
    }
}

/// Why the mass properties of a convex hull could not be computed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum HullError {
    /// Fewer than 4 points: no hull of 4 points spanning a volume can exist.
    #[error("a convex hull needs at least 4 points, got {0}")]
    TooFewPoints(usize),
    /// A point is NaN or infinite.
    #[error("point {0} of the convex hull is not finite")]
    NonFinitePoint(usize),
    /// More points than [`MAX_HULL_POINTS`].
    #[error("a convex hull takes at most {MAX_HULL_POINTS} points, got {0}")]
    TooManyPoints(usize),
    /// The hull is so thin that its volume, below [`HULL_MIN_RELATIVE_VOLUME`] of its bounding
    /// box's, is round-off: it has no usable inertia.
    #[error(
        "convex hull is degenerate: its volume {volume:.3e} m³ is below {} of its bounding \
         box's {bounding_box_volume:.3e} m³ (needs 4 points spanning a volume)",
        crate::error::compact(HULL_MIN_RELATIVE_VOLUME)
    )]
    Degenerate {
        /// The hull's volume (m³).
        volume: f64,
        /// The volume of its axis-aligned bounding box (m³).
        bounding_box_volume: f64,
    },
    /// The points lie (nearly) at one point, on a line or in a plane: within the hull
    /// algorithm's tolerance, `1e-11` of the largest coordinate, so no hull is built.
    #[error(
        "convex hull is degenerate: its points lie within {thickness:.3e} m of a {shape}, \
         within the tolerance {tolerance:.3e} m (1e-11 of the largest coordinate); needs 4 \
         points spanning a volume"
    )]
    Flat {
        /// What the points lie on: `"point"`, `"line"` or `"plane"`.
        shape: &'static str,
        /// Their largest distance from it (m).
        thickness: f64,
        /// The tolerance (m).
        tolerance: f64,
    },
    /// The hull algorithm failed on these points (numerical trouble).
    #[error("the convex hull of these points could not be computed ({0})")]
    Failed(String),
    /// The hull is valid but its mass properties are not (e.g. a mass that overflows).
    #[error(transparent)]
    Mass(#[from] InvalidInput),
}

/// Most points accepted by [`convex_hull_mass_properties`]: twice the largest measured case, so
/// the time stays bounded (about 15 s in the worst measured distribution, every point on the
/// hull).
pub const MAX_HULL_POINTS: usize = 2_000_000;

/// A hull whose volume is below this fraction of its bounding box's is rejected as flat: the
/// round-off of the integrals (relative `~1e-12` in `f64`, `~1e-6` when the hull was computed
/// in `f32`) would otherwise be all of its inertia.
pub const HULL_MIN_RELATIVE_VOLUME: f64 = 1e-9;

/// Mass properties of the convex hull of `points` (in body coordinates) made of a uniform
/// material of the given `density`.
///
/// The hull's triangles come from `quickhull` (in `f64`); the volume, centre of mass and inertia
/// tensor are then integrated here, in `f64`, over the tetrahedra that join each triangle to a
/// point inside the hull (the mean of the hull's vertices, so that no tetrahedron is far from
/// the origin and nothing cancels), and the tensor is diagonalised by Jacobi rotations. parry's
/// own `ConvexPolyhedron` mass properties lose everything to `f32` cancellation for hulls of
/// 1e5 vertices and more (they came out as mass 0).
///
/// Time: `O(n log n)` expected (see `quickhull`). Measured in a release build on a shared
/// 2-core machine: 1e5 points 0.03 s in a ball or on a cube, 0.3–0.7 s all on a sphere (every
/// point a vertex); 1e6 points 0.45–0.6 s in a ball or on a cube, 4–6 s all on a sphere. Inputs
/// are capped at [`MAX_HULL_POINTS`].
///
/// Accuracy: `f64` integrals of the exact hull of the points (up to the `eps` of
/// `quickhull`), rounded once to [`crate::math::Real`]; a cube given by its corners and face
/// points gives the cuboid to round-off, `n` random points on a sphere give a hull whose
/// volume is short of the ball's by the discretisation (`1.2e-2` at 1e3 points, `1.2e-4` at 1e5,
/// `1.2e-5` at 1e6).
pub fn convex_hull_mass_properties(
    points: &[Vec3],
    density: Density,
) -> Result<MassProperties, HullError> {
    if points.len() < 4 {
        return Err(HullError::TooFewPoints(points.len()));
    }
    if points.len() > MAX_HULL_POINTS {
        return Err(HullError::TooManyPoints(points.len()));
    }
    if let Some(i) = points.iter().position(|p| !p.is_finite()) {
        return Err(HullError::NonFinitePoint(i));
    }
    let (vertices, triangles) = hull_triangles(points)?;
    let integrals = integrate_closed_surface(&vertices, &triangles);
    let (lo, hi) = vertices.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), v| (lo.min(*v), hi.max(*v)),
    );
    let bounding_box_volume = (hi - lo).element_product();
    let solid = integrals.volume > HULL_MIN_RELATIVE_VOLUME * bounding_box_volume;
    if !solid {
        return Err(HullError::Degenerate {
            volume: integrals.volume,
            bounding_box_volume,
        });
    }
    integrals.mass_properties(to_f64(density.get()))
}

/// Volume integrals of a closed triangulated surface: volume, centre of mass and the second
/// moment `∫ (x − c)(x − c)ᵀ dV` about the centre of mass.
struct VolumeIntegrals {
    volume: f64,
    center: DVec3,
    second_moment: DMat3,
}

impl VolumeIntegrals {
    /// Mass properties for a uniform `density`.
    fn mass_properties(&self, density: f64) -> Result<MassProperties, HullError> {
        let mass = Mass::new((density * self.volume).narrow())?;
        // I = ρ (tr(C) E − C).
        let c = self.second_moment;
        let trace = c.x_axis.x + c.y_axis.y + c.z_axis.z;
        let tensor = (DMat3::from_diagonal(DVec3::splat(trace)) - c) * density;
        let (moments, frame) = symmetric_eigen(tensor);
        // Round-off can leave a tiny negative moment for a very thin hull: clamp it to 0 only
        // when it is round-off (far below the largest moment), so real garbage still fails.
        let largest = moments.max_element();
        let moments = moments.map(|m| {
            if m < 0.0 && -m < 1e-9 * largest {
                0.0
            } else {
                m
            }
        });
        Ok(MassProperties::new(mass, moments.narrow())?
            .with_principal_frame(frame.narrow())?
            .with_center_of_mass(self.center.narrow())?)
    }
}

/// Integrates over the tetrahedra joining each triangle to the mean of the vertices. The
/// orientation of the triangles may be either way (all the same): the sign of the total volume
/// says which.
fn integrate_closed_surface(vertices: &[DVec3], triangles: &[[u32; 3]]) -> VolumeIntegrals {
    let origin = vertices.iter().copied().sum::<DVec3>() / vertices.len().max(1) as f64;
    let mut volume = 0.0;
    let mut first = DVec3::ZERO;
    let mut second = DMat3::ZERO;
    for t in triangles {
        let [a, b, c] = t.map(|i| vertices[i as usize] - origin);
        // Signed volume of the tetrahedron (0, a, b, c).
        let v = a.dot(b.cross(c)) / 6.0;
        let s = a + b + c;
        volume += v;
        first += v * s / 4.0;
        // ∫ x xᵀ dV over the tetrahedron = v/20 (a aᵀ + b bᵀ + c cᵀ + s sᵀ).
        second += (outer(a, a) + outer(b, b) + outer(c, c) + outer(s, s)) * (v / 20.0);
    }
    if volume < 0.0 {
        volume = -volume;
        first = -first;
        second = -second;
    }
    let d = if volume > 0.0 {
        first / volume
    } else {
        DVec3::ZERO
    };
    VolumeIntegrals {
        volume,
        center: origin + d,
        // Parallel-axis shift from `origin` to the centre of mass.
        second_moment: second - outer(d, d) * volume,
    }
}

/// `a bᵀ`.
fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}

/// Eigenvalues and the rotation whose columns are the eigenvectors of a symmetric matrix, by
/// cyclic Jacobi rotations (converges quadratically; 3×3 needs a handful of sweeps).
fn symmetric_eigen(m: DMat3) -> (DVec3, DQuat) {
    let mut a = m.to_cols_array_2d(); // a[col][row]; symmetric, so a[i][j] = a[j][i].
    let mut v = DMat3::IDENTITY.to_cols_array_2d();
    for _ in 0..32 {
        let off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
        let diag = a[0][0] * a[0][0] + a[1][1] * a[1][1] + a[2][2] * a[2][2];
        if off <= 1e-30 * diag {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            if a[p][q] == 0.0 {
                continue;
            }
            let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            // A ← Jᵀ A J with J the rotation in the (p, q) plane.
            for row in a.iter_mut() {
                let (akp, akq) = (row[p], row[q]);
                row[p] = c * akp - s * akq;
                row[q] = s * akp + c * akq;
            }
            let (rp, rq) = (a[p], a[q]);
            a[p] = std::array::from_fn(|k| c * rp[k] - s * rq[k]);
            a[q] = std::array::from_fn(|k| s * rp[k] + c * rq[k]);
            for row in &mut v {
                let (vp, vq) = (row[p], row[q]);
                row[p] = c * vp - s * vq;
                row[q] = s * vp + c * vq;
            }
        }
    }
    // `v` was updated as rows of Vᵀ ... transpose back to eigenvectors as columns.
    let mut vecs = DMat3::from_cols_array_2d(&v).transpose();
    if vecs.determinant() < 0.0 {
        vecs.z_axis = -vecs.z_axis;
    }
    let frame = DQuat::from_mat3(&vecs).normalize();
    (DVec3::new(a[0][0], a[1][1], a[2][2]), frame)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{Real, to_f64};

    /// A ball against `m = ρ 4/3 π r³`, `I = 2/5 m r²` in every precision combination (parry
    /// integrates in its own precision: a few ulps of `f32` at worst).
    #[test]
    fn ball_mass_properties_match_the_closed_form() {
        let (rho, r) = (1000.0, 0.5);
        let props = mass_properties_of(
            &parry::shape::Ball::new(0.5),
            Density::new(rho as Real).unwrap(),
        )
        .unwrap();
        let m = rho * 4.0 / 3.0 * std::f64::consts::PI * r * r * r;
        let tolerance = 1e-5;
        assert!((to_f64(props.mass()) / m - 1.0).abs() < tolerance);
        let inertia = props.principal_inertia();
        for moment in [inertia.x, inertia.y, inertia.z] {
            assert!((to_f64(moment) / (0.4 * m * r * r) - 1.0).abs() < tolerance);
        }
    }

    /// Every shape kind a scene can name, from chunky to very thin, yields mass properties that
    /// pass `MassProperties::new`'s checks (triangle inequality with its slack, reciprocals).
    #[test]
    fn every_shape_kind_passes_validation_also_when_thin() {
        use parry::shape::{Ball, Capsule, Cone, Cuboid, Cylinder};
        let rho = Density::new(1000.0).unwrap();
        let mut shapes: Vec<(String, Box<dyn Shape>)> = Vec::new();
        for r in [1e-3, 0.5, 100.0] {
            shapes.push((format!("ball {r}"), Box::new(Ball::new(r))));
        }
        for (a, b) in [
            (1.0, 1.0),
            (1.0, 1e-3),
            (1e-3, 1.0),
            (1.0, 1e-5),
            (1e-5, 1.0),
        ] {
            shapes.push((
                format!("cuboid {a} {b}"),
                Box::new(Cuboid::new(parry::math::Vector::new(a, b, a))),
            ));
            shapes.push((
                format!("cuboid {a} {b} {b}"),
                Box::new(Cuboid::new(parry::math::Vector::new(a, b, b))),
            ));
            shapes.push((format!("capsule {a} {b}"), Box::new(Capsule::new_y(a, b))));
            shapes.push((format!("cylinder {a} {b}"), Box::new(Cylinder::new(a, b))));
            shapes.push((format!("cone {a} {b}"), Box::new(Cone::new(a, b))));
            // The hull takes engine-precision points; in an `f64` build on `f32` parry shapes the
            // literals above are parry's `f32`, and the hull is covered by the tests below.
            #[cfg(any(not(feature = "f64"), feature = "parry-f64"))]
            let plate = [
                Vec3::new(-a, -b, -a),
                Vec3::new(a, -b, -a),
                Vec3::new(-a, -b, a),
                Vec3::new(a, -b, a),
                Vec3::new(-a, b, -a),
                Vec3::new(a, b, -a),
                Vec3::new(-a, b, a),
                Vec3::new(a, b, a),
            ];
            #[cfg(any(not(feature = "f64"), feature = "parry-f64"))]
            convex_hull_mass_properties(&plate, rho)
                .unwrap_or_else(|e| panic!("hull plate {a} {b}: {e}"));
        }
        for (name, shape) in &shapes {
            mass_properties_of(shape.as_ref(), rho).unwrap_or_else(|e| panic!("{name}: {e}"));
        }
    }

    /// xorshift64 uniform in [-1, 1).
    fn uniform(seed: &mut u64) -> f64 {
        *seed ^= *seed << 13;
        *seed ^= *seed >> 7;
        *seed ^= *seed << 17;
        (*seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }

    /// `n` random points: on the unit sphere, in the unit ball, or on the surface of the cube
    /// `[-1, 1]³` with its 8 corners first.
    fn cloud(n: usize, kind: &str) -> Vec<Vec3> {
        let mut seed = 0x9e37_79b9_7f4a_7c15_u64;
        let mut points = Vec::with_capacity(n);
        if kind == "cube" {
            for i in 0..8 {
                let s = |bit: usize| if i >> bit & 1 == 1 { 1.0 } else { -1.0 };
                points.push(DVec3::new(s(0), s(1), s(2)).narrow());
            }
        }
        while points.len() < n {
            let v = DVec3::new(uniform(&mut seed), uniform(&mut seed), uniform(&mut seed));
            let length = v.length();
            if !(1e-3..=1.0).contains(&length) {
                continue;
            }
            let p = match kind {
                "sphere" => v / length,
                "ball" => v,
                _ => {
                    // Push one coordinate onto a face.
                    let axis = (uniform(&mut seed).abs() * 3.0) as usize % 3;
                    let mut p = v;
                    p[axis] = p[axis].signum();
                    p
                }
            };
            points.push(p.narrow());
        }
        points
    }

    fn relative(a: f64, b: f64) -> f64 {
        (a / b - 1.0).abs()
    }

    /// A cube given by its corners and points on its faces: exactly the cuboid (round-off).
    #[test]
    fn hull_of_points_on_a_cube_is_the_cuboid() {
        let rho = Density::new(2.0).unwrap();
        for n in [8, 1000, 100_000] {
            let props = convex_hull_mass_properties(&cloud(n, "cube"), rho).unwrap();
            let exact = MassProperties::solid_cuboid(Mass::new(16.0).unwrap(), Vec3::ONE).unwrap();
            assert!(
                relative(to_f64(props.mass()), 16.0) < 1e-6,
                "{n}: {}",
                props.mass()
            );
            for (a, b) in props
                .principal_inertia()
                .to_array()
                .into_iter()
                .zip(exact.principal_inertia().to_array())
            {
                assert!(relative(to_f64(a), to_f64(b)) < 1e-6, "{n}: {a} vs {b}");
            }
            assert!(props.local_center_of_mass().length() < 1e-5);
        }
    }

    /// Points on a sphere, or in a ball: the hull approaches the ball (`m = ρ 4/3 π`,
    /// `I = 2/5 m`) from inside, within the discretisation error of its `n` points.
    #[test]
    fn hull_of_many_points_on_or_in_a_sphere_is_the_ball() {
        let rho = Density::new(1.0).unwrap();
        let m = 4.0 / 3.0 * std::f64::consts::PI;
        for (n, kind, tolerance) in [
            (1_000, "sphere", 2e-2),
            (100_000, "ball", 2e-2),
            (100_000, "sphere", 2e-4),
            (1_000_000, "sphere", 2e-5),
            (1_000_000, "ball", 1e-2),
        ] {
            let start = std::time::Instant::now();
            let props = convex_hull_mass_properties(&cloud(n, kind), rho).unwrap();
            eprintln!(
                "{n} points on a {kind}: mass error {:e}, {:?}",
                relative(to_f64(props.mass()), m),
                start.elapsed()
            );
            assert!(
                relative(to_f64(props.mass()), m) < tolerance,
                "{n} on a {kind}: mass {}",
                props.mass()
            );
            for moment in props.principal_inertia().to_array() {
                assert!(
                    relative(to_f64(moment), 0.4 * m) < 2.0 * tolerance,
                    "{moment}"
                );
            }
        }
    }

    #[test]
    fn degenerate_hulls_are_clear_errors() {
        let rho = Density::new(1.0).unwrap();
        let flat: Vec<Vec3> = (0..100)
            .map(|i| Vec3::new((i % 10) as Real, (i / 10) as Real, 0.0))
            .collect();
        assert!(convex_hull_mass_properties(&flat, rho).is_err());
        assert_eq!(
            convex_hull_mass_properties(&[Vec3::ZERO; 3], rho),
            Err(HullError::TooFewPoints(3))
        );
        let mut bad = cloud(10, "ball");
        bad[4].y = Real::NAN;
        assert_eq!(
            convex_hull_mass_properties(&bad, rho),
            Err(HullError::NonFinitePoint(4))
        );
        // A needle 1e12 m long and about 1 m thick, and a plate 1e-11 thick: refused before a
        // hull is built, each with the distance it has from a line or a plane and the
        // tolerance (1e-11 of the largest coordinate), not zeros or a volume ratio it does
        // not fail.
        let needle = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z, Vec3::splat(1e12)];
        let plate = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(0.0, 0.0, 1e-11)];
        for (points, shape, thickness, tolerance) in [
            (&needle[..], "line", 0.82, 10.0),
            (&plate[..], "plane", 1e-11, 1e-11),
        ] {
            match convex_hull_mass_properties(points, rho) {
                Err(HullError::Flat {
                    shape: s,
                    thickness: t,
                    tolerance: e,
                }) => {
                    assert_eq!(s, shape);
                    assert!((t / thickness - 1.0).abs() < 1e-2, "{t}");
                    assert!((e / tolerance - 1.0).abs() < 1e-6, "{e}");
                }
                other => panic!("{shape}: {other:?}"),
            }
        }
    }
}
