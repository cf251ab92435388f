//! Mass properties from parry3d shapes against closed forms, and the Mass/Density split.

use tumble::math::{Quat, Real, Vec3, to_f64};
use tumble::parry::math::Pose;
use tumble::parry::shape::{
    Ball, Capsule, Compound, Cone, ConvexPolyhedron, Cuboid, Cylinder, Shape, SharedShape,
};
use tumble::prelude::*;

const PI: f64 = std::f64::consts::PI;
/// parry integrates in f32: a few ulps of relative error on closed-form shapes.
const TOL: f64 = 1e-5;

fn rho() -> Density {
    Density::new(750.0).unwrap()
}

fn close(a: Real, b: f64, tol: f64, what: &str) {
    let r = (to_f64(a) - b).abs() / b.abs();
    assert!(r < tol, "{what}: {a} vs {b} (rel {r:e})");
}

/// The mass properties (density 750 kg/m³) of the round shape along y of half height `hh` and
/// radius `r` that `new(hh, r)` builds, and its full height.
fn along_y<S: Shape>(hh: f64, r: f64, new: fn(Real, Real) -> S) -> (MassProperties, f64) {
    let props = mass_properties_of(&new(hh as Real, r as Real), rho()).unwrap();
    (props, 2.0 * hh)
}

/// [`close`] with [`TOL`] for each `(value, closed form, what)`.
fn closed_forms(checks: &[(Real, f64, &str)]) {
    for &(a, b, what) in checks {
        close(a, b, TOL, what);
    }
}

/// [`close`] for each of `values` against the one expected `b` (moments equal by symmetry).
fn all_close(values: &[Real], b: f64, tol: f64, what: &str) {
    for &a in values {
        close(a, b, tol, what);
    }
}

/// Sorted principal moments (parry may order axes its own way for hulls and compounds).
fn sorted(v: Vec3) -> [Real; 3] {
    let mut a = v.to_array();
    a.sort_by(Real::total_cmp);
    a
}

#[test]
fn ball_is_two_fifths_m_r_squared() {
    let r = 0.3_f64;
    let props = mass_properties_of(&Ball::new(r as Real), rho()).unwrap();
    let m = 750.0 * 4.0 / 3.0 * PI * r.powi(3);
    close(props.mass(), m, TOL, "ball mass");
    for i in props.principal_inertia().to_array() {
        close(i, 0.4 * m * r * r, TOL, "ball inertia");
    }
    assert!(props.is_spherical());
}

#[test]
fn cuboid_is_m_b2_c2_over_12() {
    let (a, b, c) = (0.8_f64, 0.3, 0.1); // full edges
    let shape = Cuboid::new(Vec3::new(a as Real, b as Real, c as Real) * 0.5);
    let props = mass_properties_of(&shape, rho()).unwrap();
    let m = 750.0 * a * b * c;
    let i = props.principal_inertia();
    // The closed-form constructor agrees.
    let direct =
        MassProperties::solid_cuboid(Mass::new(m as Real).unwrap(), shape.half_extents).unwrap();
    closed_forms(&[
        (props.mass(), m, "box mass"),
        (i.x, m * (b * b + c * c) / 12.0, "box Ixx"),
        (i.y, m * (a * a + c * c) / 12.0, "box Iyy"),
        (i.z, m * (a * a + b * b) / 12.0, "box Izz"),
        (
            direct.principal_inertia().y,
            m * (a * a + c * c) / 12.0,
            "solid_cuboid",
        ),
    ]);
}

#[test]
fn cylinder_axial_half_m_r2_transverse_m_3r2_h2_over_12() {
    let (hh, r) = (0.4_f64, 0.15);
    let (props, h) = along_y(hh, r, Cylinder::new);
    let m = 750.0 * PI * r * r * h;
    let i = props.principal_inertia();
    let transverse = m * (3.0 * r * r + h * h) / 12.0;
    closed_forms(&[
        (props.mass(), m, "cylinder mass"),
        (i.y, 0.5 * m * r * r, "cylinder axial (y)"),
        (i.x, transverse, "cylinder transverse"),
        (i.z, transverse, "cylinder transverse"),
    ]);
}

#[test]
fn cone_moments_and_centre_of_mass() {
    let (hh, r) = (0.5_f64, 0.2);
    let (props, h) = along_y(hh, r, Cone::new);
    let m = 750.0 * PI * r * r * h / 3.0;
    let i = props.principal_inertia();
    closed_forms(&[
        (props.mass(), m, "cone mass"),
        (i.y, 0.3 * m * r * r, "cone axial"),
        // About the centre of mass: 3/20 m r² + 3/80 m h².
        (
            i.x,
            0.15 * m * r * r + 3.0 / 80.0 * m * h * h,
            "cone transverse",
        ),
        // Centre of mass a quarter of the height above the base (base at y = −h/2).
        (props.local_center_of_mass().y, -hh + h / 4.0, "cone com"),
    ]);
}

#[test]
fn capsule_is_cylinder_plus_two_hemispheres() {
    let (hh, r) = (0.3_f64, 0.1);
    let (props, h) = along_y(hh, r, Capsule::new_y);
    let m_cyl = 750.0 * PI * r * r * h;
    let m_sph = 750.0 * 4.0 / 3.0 * PI * r.powi(3);
    close(props.mass(), m_cyl + m_sph, TOL, "capsule mass");
    let axial = m_cyl * r * r / 2.0 + m_sph * 0.4 * r * r;
    // Hemisphere about its own centre of mass (3r/8 from the flat face), then shifted.
    let transverse = m_cyl * (h * h / 12.0 + r * r / 4.0)
        + m_sph * (0.4 * r * r + h * h / 4.0 + 3.0 * h * r / 8.0);
    let i = props.principal_inertia();
    close(i.y, axial, TOL, "capsule axial");
    close(i.x, transverse, TOL, "capsule transverse");
}

#[test]
fn convex_hull_of_box_corners_is_the_box() {
    let half = Vec3::new(0.5, 0.2, 0.1);
    let corners: Vec<Vec3> = (0..8)
        .map(|k| {
            let s = |bit: i32| if k & bit != 0 { 1.0 } else { -1.0 };
            Vec3::new(s(1) * half.x, s(2) * half.y, s(4) * half.z)
        })
        .collect();
    let hull = ConvexPolyhedron::from_convex_hull(&corners).unwrap();
    let props = mass_properties_of(&hull, rho()).unwrap();
    let (a, b, c) = (1.0_f64, 0.4, 0.2);
    let m = 750.0 * a * b * c;
    close(props.mass(), m, 1e-4, "hull mass");
    let expected = [
        m * (a * a + b * b),
        m * (a * a + c * c),
        m * (b * b + c * c),
    ]
    .map(|x| x / 12.0);
    let got = sorted(props.principal_inertia());
    let mut want = expected;
    want.sort_by(f64::total_cmp);
    for (g, w) in got.iter().zip(want) {
        close(*g, w, 1e-4, "hull inertia");
    }
    assert!(props.local_center_of_mass().length() < 1e-5);
}

#[test]
fn compound_of_two_balls_obeys_parallel_axes() {
    let r = 0.1_f64;
    let d = 0.5_f64; // each ball at ±d on x
    let ball = SharedShape::ball(r as Real);
    let compound = Compound::new(vec![
        (
            Pose::from_translation(Vec3::new(d as Real, 0.0, 0.0)),
            ball.clone(),
        ),
        (
            Pose::from_translation(Vec3::new(-d as Real, 0.0, 0.0)),
            ball,
        ),
    ]);
    let props = mass_properties_of(&compound, rho()).unwrap();
    let m1 = 750.0 * 4.0 / 3.0 * PI * r.powi(3);
    close(props.mass(), 2.0 * m1, TOL, "compound mass");
    let own = 0.4 * m1 * r * r;
    let got = sorted(props.principal_inertia());
    close(got[0], 2.0 * own, 1e-4, "compound axial");
    all_close(
        &got[1..],
        2.0 * (own + m1 * d * d),
        1e-4,
        "compound transverse",
    );
    // The principal frame maps the smallest moment's axis onto world x.
    let frame: Quat = props.principal_frame();
    let inertia = props.principal_inertia().to_array();
    let smallest = (0..3)
        .min_by(|&i, &j| inertia[i].total_cmp(&inertia[j]))
        .unwrap();
    let axis = frame * Vec3::AXES[smallest];
    assert!(
        axis.x.abs() > 0.999,
        "smallest-moment axis {axis} should be ±x"
    );
}

#[test]
fn mass_and_density_reject_bad_values() {
    for bad in [0.0, -1.0, Real::NAN, Real::INFINITY] {
        assert!(Mass::new(bad).is_err(), "mass {bad}");
        assert!(Density::new(bad).is_err(), "density {bad}");
    }
    let one = Mass::new(1.0).unwrap();
    assert!(MassProperties::new(one, Vec3::new(1.0, -1.0, 1.0)).is_err());
    assert!(MassProperties::new(one, Vec3::ZERO).is_err());
    assert!(MassProperties::new(one, Vec3::new(1.0, Real::NAN, 1.0)).is_err());
    assert!(
        MassProperties::new(one, Vec3::ONE)
            .unwrap()
            .with_principal_frame(Quat::from_xyzw(0.0, 0.0, 0.0, 2.0))
            .is_err()
    );
    // A flat shape has no volume, hence no mass.
    let flat = Cuboid::new(Vec3::new(1.0, 0.0, 1.0));
    assert!(mass_properties_of(&flat, rho()).is_err());
}
