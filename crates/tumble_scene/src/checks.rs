//! The checks of a scene's values: the world settings, the bodies and the forces, each error
//! naming the file, the line and the field.

use std::borrow::Cow;
use std::collections::HashMap;
use std::num::NonZeroU32;
use tumble_core::math::{Quat, REAL_NAME, Real, Vec3, Widen, quat_normalize};

use bevy_ecs::prelude::*;

use tumble_core::shapes::parry::shape::{Ball, Capsule, Cone, Cuboid, Cylinder};
use tumble_core::shapes::{HullError, convex_hull_mass_properties, mass_properties_of};
use tumble_core::{Density, Integrator, Mass, MassProperties};
use tumble_ecs::prelude::*;

use crate::error::SceneError;
use crate::format::{BodyDef, ForceDef, SceneFile, ShapeDef, WorldDef};
use crate::text::{is_unsafe_char, terminal_safe};
use crate::validate::{Checker, NoText};
use tumble_core::error::compact;

use crate::model::{MAX_STEPS, MAX_SUBSTEPS, SceneForce, ValidBody};

/// Body `i` of a scene in engine form: [`validate_body`] again, which cannot fail on a body
/// that passed it when the scene was parsed (a `Scene`'s model is not changed in place).
pub(crate) fn checked_body(file: &str, i: usize, def: &BodyDef) -> ValidBody {
    let ck = Checker {
        file,
        locate: &NoText,
    };
    validate_body(&ck, i, def).unwrap_or_else(|e| {
        unreachable!("body {i} passed this check when the scene was parsed: {e}")
    })
}

/// The world settings of a scene, checked.
pub(crate) struct CheckedWorld {
    pub(crate) settings: PhysicsSettings,
    pub(crate) steps: u64,
    pub(crate) gravity: Option<Vec3>,
}

pub(crate) fn validate_world(ck: &Checker<'_>, w: &WorldDef) -> Result<CheckedWorld, SceneError> {
    let dt = ck.scalar("world", None, "dt", w.dt)?;
    if w.dt <= 0.0 {
        return Err(ck.error(
            "world",
            None,
            "dt",
            format!("expected a time step > 0, got {}", compact(w.dt)),
        ));
    }
    if w.steps == 0 || w.steps > MAX_STEPS {
        return Err(ck.error(
            "world",
            None,
            "steps",
            format!("expected 1 to {MAX_STEPS} steps, got {}", w.steps),
        ));
    }
    let integrator = match &w.integrator {
        None => Integrator::default(),
        Some(name) => name
            .parse()
            .map_err(|e: tumble_core::integrate::UnknownIntegrator| {
                ck.error("world", None, "integrator", e.to_string())
            })?,
    };
    let springs = match &w.springs {
        None => SpringSolver::default(),
        Some(name) => name
            .parse()
            .map_err(|e: String| ck.error("world", None, "springs", e))?,
    };
    let free_flow = match &w.free_flow {
        None => FreeFlow::default(),
        Some(name) => name
            .parse()
            .map_err(|e: String| ck.error("world", None, "free_flow", e))?,
    };
    let substeps = match w.substeps {
        None => NonZeroU32::MIN,
        Some(n) => u32::try_from(n)
            .ok()
            .filter(|&n| n <= MAX_SUBSTEPS)
            .and_then(NonZeroU32::new)
            .ok_or_else(|| {
                ck.error(
                    "world",
                    None,
                    "substeps",
                    format!("expected 1 to {MAX_SUBSTEPS} substeps, got {n}"),
                )
            })?,
    };
    let settings = PhysicsSettings::new(dt, integrator)
        .map_err(|e| ck.error("world", None, "dt", e.to_string()))?
        .with_springs(springs)
        .with_substeps(substeps)
        .map_err(|e| ck.error("world", None, "substeps", e.to_string()))?
        .with_free_flow(free_flow);
    let gravity = w
        .gravity
        .map(|g| ck.vec3("world", None, "gravity", g))
        .transpose()?;
    Ok(CheckedWorld {
        settings,
        steps: w.steps,
        gravity,
    })
}

/// Checks every force generator of the file, keeping none: a scene holds its file model once,
/// and [`checked_force`] converts each again where the world is built.
pub(crate) fn validate_forces(
    ck: &Checker<'_>,
    defs: &[ForceDef],
    names: &HashMap<&str, usize>,
) -> Result<(), SceneError> {
    for (i, f) in defs.iter().enumerate() {
        checked_force(ck, i, f, names)?;
    }
    Ok(())
}

/// Force generator `i` of the file in engine form, its bodies looked up by name in `names`.
pub(crate) fn checked_force(
    ck: &Checker<'_>,
    i: usize,
    f: &ForceDef,
    names: &HashMap<&str, usize>,
) -> Result<SceneForce, SceneError> {
    let body = |i: usize, key: &str, name: &str| {
        names.get(name).copied().ok_or_else(|| {
            ck.error(
                "forces",
                Some(i),
                key,
                format!(
                    "unknown body `{}`; expected one of the [[bodies]] names",
                    terminal_safe(name)
                ),
            )
        })
    };
    let v = |key: &str, x: [f64; 3]| ck.vec3("forces", Some(i), key, x);
    Ok(match f {
        ForceDef::Constant {
            body: b,
            force,
            point,
        } => SceneForce::Constant {
            body: body(i, "body", b)?,
            force: v("force", *force)?,
            point: point.map(|p| v("point", p)).transpose()?,
        },
        ForceDef::Torque { body: b, torque } => SceneForce::Torque {
            body: body(i, "body", b)?,
            torque: v("torque", *torque)?,
        },
        ForceDef::Spring {
            a,
            anchor_a,
            b,
            anchor_b,
            stiffness,
            damping,
            rest_length,
        } => {
            let non_negative = |key: &str, x: f64| -> Result<Real, SceneError> {
                let y = ck.scalar("forces", Some(i), key, x)?;
                if y < 0.0 {
                    return Err(ck.error(
                        "forces",
                        Some(i),
                        key,
                        format!("expected a value >= 0, got {}", compact(x)),
                    ));
                }
                Ok(y)
            };
            let a_index = body(i, "a", a)?;
            let b_index = b.as_ref().map(|b| body(i, "b", b)).transpose()?;
            if b_index == Some(a_index) {
                return Err(ck.error(
                    "forces",
                    Some(i),
                    "b",
                    format!(
                        "spring joins `{}` to itself; expected a different body, \
                             or no `b` to anchor `a` to the world point `anchor_b`",
                        terminal_safe(a)
                    ),
                ));
            }
            let k = non_negative("stiffness", *stiffness)?;
            let rest = non_negative("rest_length", *rest_length)?;
            if !(k * rest).is_finite() {
                return Err(ck.error(
                    "forces",
                    Some(i),
                    "rest_length",
                    format!(
                        "stiffness {} times rest_length {} overflows {REAL_NAME}: the spring's \
                         force at zero length must be a finite number; expected a shorter rest \
                         length or a softer spring",
                        compact(k),
                        compact(rest)
                    ),
                ));
            }
            SceneForce::Spring {
                a: a_index,
                anchor_a: v("anchor_a", *anchor_a)?,
                b: b_index,
                anchor_b: v("anchor_b", *anchor_b)?,
                k,
                c: non_negative("damping", *damping)?,
                rest,
            }
        }
    })
}

pub(crate) fn validate_body(
    ck: &Checker<'_>,
    i: usize,
    b: &BodyDef,
) -> Result<ValidBody, SceneError> {
    let t = "bodies";
    let mass = body_mass(ck, i, b)?;
    let position = ck.vec3(t, Some(i), "position", b.position)?;
    let rotation = body_rotation(ck, i, b)?;
    let linear = ck.vec3(t, Some(i), "linear_velocity", b.linear_velocity)?;
    let angular = ck.vec3(t, Some(i), "angular_velocity", b.angular_velocity)?;
    let velocity = Velocity { linear, angular };
    check_kinetic_energy(ck, i, &mass, rotation, &velocity)?;
    check_locked_axis_rates(ck, i, &mass, rotation, angular)?;
    let (gravity_scale, damping) = body_extras(ck, i, b)?;
    Ok(ValidBody {
        mass,
        transform: Pose {
            translation: position,
            rotation,
        },
        velocity,
        gravity_scale,
        damping,
    })
}

/// The body's gravity scale and damping, checked: the part of [`validate_body`] that decides
/// which optional components the body is spawned with.
pub(crate) fn body_extras(
    ck: &Checker<'_>,
    i: usize,
    b: &BodyDef,
) -> Result<(Real, Damping), SceneError> {
    let gravity_scale = ck.scalar("bodies", Some(i), "gravity_scale", b.gravity_scale)?;
    Ok((gravity_scale, body_damping(ck, i, b)?))
}

/// [`body_extras`] of a body that passed [`validate_body`] when the scene was parsed.
pub(crate) fn checked_extras(file: &str, i: usize, def: &BodyDef) -> (Real, Damping) {
    let ck = Checker {
        file,
        locate: &NoText,
    };
    body_extras(&ck, i, def).unwrap_or_else(|e| {
        unreachable!("body {i} passed this check when the scene was parsed: {e}")
    })
}

/// The body's mass properties: `mass` and `inertia`, or `shape` and `density`.
pub(crate) fn body_mass(
    ck: &Checker<'_>,
    i: usize,
    b: &BodyDef,
) -> Result<MassProperties, SceneError> {
    let t = "bodies";
    match (&b.mass, &b.inertia, &b.shape, &b.density) {
        (Some(m), Some(inertia), None, None) => {
            let m = ck.scalar(t, Some(i), "mass", *m)?;
            let mass = Mass::new(m).map_err(|e| ck.error(t, Some(i), "mass", e.to_string()))?;
            let inertia = ck.vec3(t, Some(i), "inertia", *inertia)?;
            MassProperties::new(mass, inertia)
                .map_err(|e| ck.error(t, Some(i), "inertia", e.to_string()))
        }
        (None, None, Some(shape), Some(rho)) => {
            let rho = ck.scalar(t, Some(i), "density", *rho)?;
            let density =
                Density::new(rho).map_err(|e| ck.error(t, Some(i), "density", e.to_string()))?;
            shape_mass(ck, i, shape, density)
        }
        _ => Err(ck.error(
            t,
            Some(i),
            "mass",
            "expected either `mass` and `inertia`, or `shape` and `density`",
        )),
    }
}

/// The body's rotation, of unit length within the tolerance, normalized by the engine's own
/// arithmetic (in f64, rounded once), not glam's, whose SIMD and scalar builds round
/// differently: the same file gives the same bits in every build.
pub(crate) fn body_rotation(ck: &Checker<'_>, i: usize, b: &BodyDef) -> Result<Quat, SceneError> {
    let t = "bodies";
    let mut q = [0.0 as Real; 4];
    for (o, x) in q.iter_mut().zip(b.rotation) {
        *o = ck.scalar(t, Some(i), "rotation", x)?;
    }
    let rotation = Quat::from_array(q);
    tumble_core::error::check_unit_quat("rotation", rotation).map_err(|e| {
        ck.error(
            t,
            Some(i),
            "rotation",
            format!("{e}; expected [x, y, z, w] of length 1"),
        )
    })?;
    Ok(quat_normalize(rotation))
}

/// The engine computes ½m|v|² and ½ωᵀIω in its precision (energy reports, the divergence
/// check): both must be finite there, or the body is garbage from step 0.
pub(crate) fn check_kinetic_energy(
    ck: &Checker<'_>,
    i: usize,
    mass: &MassProperties,
    rotation: Quat,
    velocity: &Velocity,
) -> Result<(), SceneError> {
    let overflow = |key: &str, what: &str, value: Real| {
        ck.error(
            "bodies",
            Some(i),
            key,
            format!(
                "initial kinetic energy overflows {REAL_NAME} ({what} = {}); expected a smaller \
                 velocity",
                compact(value)
            ),
        )
    };
    let linear_energy = 0.5 * mass.mass() * velocity.linear.length_squared();
    if !linear_energy.is_finite() {
        return Err(overflow("linear_velocity", "½m|v|²", linear_energy));
    }
    let angular = velocity.angular;
    let angular_energy = 0.5 * mass.world_inertia_mul(rotation, angular).dot(angular);
    if !angular_energy.is_finite() {
        return Err(overflow("angular_velocity", "½ωᵀIω", angular_energy));
    }
    if !(linear_energy + angular_energy).is_finite() {
        return Err(overflow(
            "angular_velocity",
            "½m|v|² + ½ωᵀIω",
            linear_energy + angular_energy,
        ));
    }
    Ok(())
}

/// A zero moment locks its axis and every integrator holds the rate about it at 0: a rate
/// given there would vanish in the first step, so a file's is refused rather than dropped (the
/// library's planner warns of it).
pub(crate) fn check_locked_axis_rates(
    ck: &Checker<'_>,
    i: usize,
    mass: &MassProperties,
    rotation: Quat,
    angular: Vec3,
) -> Result<(), SceneError> {
    let locked = mass.locked_axis_rates(rotation, angular);
    if locked.length() <= tumble_ecs::stability::LOCKED_RATE_LIMIT * angular.length() {
        return Ok(());
    }
    let axes: Vec<&str> = ["x", "y", "z"]
        .into_iter()
        .zip(locked.to_array())
        .filter(|(_, rate)| *rate != 0.0)
        .map(|(axis, _)| axis)
        .collect();
    Err(ck.error(
        "bodies",
        Some(i),
        "angular_velocity",
        format!(
            "turns at {} rad/s about the locked principal axis {} (a zero moment of inertia \
             holds the rate about its axis at 0); expected no rate about it",
            compact(locked.length()),
            axes.join(" and ")
        ),
    ))
}

/// The body's damping coefficients, each `>= 0`.
pub(crate) fn body_damping(ck: &Checker<'_>, i: usize, b: &BodyDef) -> Result<Damping, SceneError> {
    let t = "bodies";
    let mut damping = Damping::default();
    for (key, value, out) in [
        ("linear_damping", b.linear_damping, &mut damping.linear),
        ("angular_damping", b.angular_damping, &mut damping.angular),
    ] {
        *out = ck.scalar(t, Some(i), key, value)?;
        if *out < 0.0 {
            return Err(ck.error(
                t,
                Some(i),
                key,
                format!("expected a value >= 0, got {}", compact(value)),
            ));
        }
    }
    Ok(damping)
}

pub(crate) fn shape_mass(
    ck: &Checker<'_>,
    i: usize,
    shape: &ShapeDef,
    density: Density,
) -> Result<MassProperties, SceneError> {
    let positive = |x: f64| -> Result<Real, SceneError> {
        let y = ck.scalar("bodies", Some(i), "shape", x)?;
        if y <= 0.0 {
            return Err(ck.error(
                "bodies",
                Some(i),
                "shape",
                format!("expected dimensions > 0, got {}", compact(x)),
            ));
        }
        Ok(y)
    };
    let result = match shape {
        ShapeDef::Ball(r) => mass_properties_of(&Ball::new(positive(*r)?), density),
        ShapeDef::Cuboid(h) => mass_properties_of(
            &Cuboid::new(Vec3::new(positive(h[0])?, positive(h[1])?, positive(h[2])?)),
            density,
        ),
        ShapeDef::Capsule([hh, r]) => {
            mass_properties_of(&Capsule::new_y(positive(*hh)?, positive(*r)?), density)
        }
        ShapeDef::Cylinder([hh, r]) => {
            mass_properties_of(&Cylinder::new(positive(*hh)?, positive(*r)?), density)
        }
        ShapeDef::Cone([hh, r]) => {
            mass_properties_of(&Cone::new(positive(*hh)?, positive(*r)?), density)
        }
        ShapeDef::ConvexHull(points) => {
            let pts: Vec<Vec3> = points
                .iter()
                .map(|p| ck.vec3("bodies", Some(i), "shape", *p))
                .collect::<Result<_, _>>()?;
            return convex_hull_mass_properties(&pts, density).map_err(|e| match e {
                HullError::Mass(e) => mass_error(ck, i, e),
                e => ck.error("bodies", Some(i), "shape", e.to_string()),
            });
        }
    };
    result.map_err(|e| match analytic_volume(shape) {
        // Dimensions and density are > 0: only the range of the precision can make a solid
        // shape's mass properties fail (parry's `mass()` reads an overflowed mass as 0).
        Some(volume) => range_error(ck, i, volume, density.get().widen()),
        None => mass_error(ck, i, e),
    })
}

/// The volume of a shape given by its dimensions, in `f64` (m³): parry computes it in the
/// engine's precision, whose range it can leave while the dimensions do not. `None` for a hull.
fn analytic_volume(shape: &ShapeDef) -> Option<f64> {
    use std::f64::consts::PI;
    let ball = |r: f64| 4.0 / 3.0 * PI * r * r * r;
    match *shape {
        ShapeDef::Ball(r) => Some(ball(r)),
        ShapeDef::Cuboid([x, y, z]) => Some(8.0 * x * y * z),
        ShapeDef::Capsule([hh, r]) => Some(PI * r * r * 2.0 * hh + ball(r)),
        ShapeDef::Cylinder([hh, r]) => Some(PI * r * r * 2.0 * hh),
        ShapeDef::Cone([hh, r]) => Some(PI * r * r * 2.0 * hh / 3.0),
        ShapeDef::ConvexHull(_) => None,
    }
}

/// The mass properties of a solid shape of `volume` (m³, `f64`) and `density` left the range
/// of the precision: says where, with the mass `ρV` in `f64` (the engine's own number reads an
/// overflowed mass as 0).
fn range_error(ck: &Checker<'_>, i: usize, volume: f64, density: f64) -> SceneError {
    let mass = volume * density;
    let (largest, smallest) = (Real::MAX.widen(), Real::MIN_POSITIVE.widen());
    let why = if mass > largest || mass.is_nan() {
        format!("the mass ρV = {mass:.3e} kg is past {REAL_NAME}'s largest number ({largest:.3e})")
    } else if mass < smallest {
        format!("the mass ρV = {mass:.3e} kg is below {REAL_NAME}'s smallest normal number")
    } else {
        format!(
            "the volume ({volume:.3e} m³) or the moments of inertia leave {REAL_NAME}'s range \
             (mass ρV = {mass:.3e} kg)"
        )
    };
    mass_error(ck, i, why)
}

/// A shape whose mass properties are not valid, and why.
pub(crate) fn mass_error(ck: &Checker<'_>, i: usize, e: impl std::fmt::Display) -> SceneError {
    ck.error(
        "bodies",
        Some(i),
        "shape",
        format!(
            "{e}: expected dimensions and a density whose mass and moments of inertia are \
             finite and > 0 in {REAL_NAME}"
        ),
    )
}

/// Puts every name of the model (the scene's, the bodies', and those the forces refer to) in
/// Unicode normalization form C, so that one name typed composed (`é`, U+00E9) and decomposed
/// (`e` + U+0301) is one name: two bodies cannot differ by it alone, and a force finds its body
/// either way. Names already composed (almost all) are not copied.
pub(crate) fn compose_names(model: &mut SceneFile) {
    let compose = |name: &mut String| {
        if let Cow::Owned(composed) = crate::text::composed(name) {
            *name = composed;
        }
    };
    compose(&mut model.name);
    for body in &mut model.bodies {
        compose(&mut body.name);
    }
    for force in &mut model.forces {
        match force {
            ForceDef::Constant { body, .. } | ForceDef::Torque { body, .. } => compose(body),
            ForceDef::Spring { a, b, .. } => {
                compose(a);
                if let Some(b) = b {
                    compose(b);
                }
            }
        }
    }
}

/// Characters that print as nothing yet are neither whitespace nor format characters (those are
/// refused by [`is_unsafe_char`]): the Hangul fillers, the Braille blank, the combining grapheme
/// joiner, the Khmer inherent vowels, and the variation selectors. A name made only of these and
/// whitespace would print blank.
pub(crate) fn prints_blank(c: char) -> bool {
    matches!(
        c as u32,
        0x115F | 0x1160 | 0x3164 | 0xFFA0 | 0x2800 | 0x034F | 0x17B4 | 0x17B5
            | 0x180B..=0x180F
            | 0xFE00..=0xFE0F
            | 0xE0100..=0xE01EF
    )
}

/// Longest scene or body name, in bytes.
pub const MAX_NAME_BYTES: usize = 256;

/// Why a name (scene or body) cannot be used, if it cannot: names are echoed to terminals and
/// written into CSV and report files, so they are non-empty, at most [`MAX_NAME_BYTES`] long
/// and free of control and format characters ([`is_unsafe_char`]: newlines, ESC, bidi
/// overrides, zero-width characters).
pub(crate) fn bad_text(name: &str) -> Option<String> {
    if name.trim().is_empty() {
        return Some("expected a non-empty name".to_owned());
    }
    if name.chars().all(|c| c.is_whitespace() || prints_blank(c)) {
        return Some(format!(
            "name `{}` prints blank; expected a name with a visible character",
            name.escape_unicode()
        ));
    }
    if name.len() > MAX_NAME_BYTES {
        return Some(format!(
            "name is {} bytes long; expected at most {MAX_NAME_BYTES}",
            name.len()
        ));
    }
    if let Some(c) = name.chars().find(|&c| is_unsafe_char(c)) {
        return Some(format!(
            "name `{}` contains the control or format character {}; expected printable text \
             that fits in one CSV cell",
            terminal_safe(name),
            c.escape_unicode()
        ));
    }
    None
}

/// Why a body name cannot be used, if it cannot: [`bad_text`], and names are CSV cells that
/// must stay one cell and must not be run by a spreadsheet.
pub(crate) fn bad_name(name: &str) -> Option<String> {
    if let Some(why) = bad_text(name) {
        return Some(why);
    }
    if name.chars().any(|c| c == ',' || c == '"') {
        return Some(format!(
            "name `{}` contains a comma or a quote; expected a name that fits in one CSV cell",
            terminal_safe(name)
        ));
    }
    if name.starts_with(['=', '+', '-', '@']) {
        return Some(format!(
            "name `{}` begins with `{}`, which a spreadsheet opening the CSV would run as a \
             formula; expected a name beginning with another character",
            terminal_safe(name),
            &name[..1]
        ));
    }
    None
}
