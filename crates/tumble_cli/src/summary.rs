//! What `tumble run` and `tumble compare` say about a world: the invariants of its summary,
//! planning-time warnings and quarantined bodies, each naming bodies and forces as the scene file
//! does.

use bevy_ecs::prelude::*;
use glam::DVec3;
use tumble_core::math::{Vec3, Widen};
use tumble_ecs::components::kinetic_energy_f64;
use tumble_ecs::prelude::*;
use tumble_scene::text::terminal_safe;

/// The kinds of force generator a scene spawns, as [`Names`] calls them.
const FORCE_KINDS: [&str; 3] = ["spring", "constant force", "torque"];

/// Names of a built scene's entities: bodies by their `name`, force generators as
/// `forces[i] (kind)` in file order.
///
/// Compact for a million bodies (about 20 bytes a body, 12 a force): the names are kept in one
/// string and looked up by a binary search over the entities, and a message (a force's name
/// too) is formatted only when one is printed.
pub(crate) struct Names {
    /// `(entity, start, end)` of each body's name in `text`, sorted by entity.
    bodies: Vec<(Entity, u32, u32)>,
    /// Every body name, one after the other.
    text: String,
    /// Each force generator and its kind (an index into [`FORCE_KINDS`]), in file order: by
    /// entity index. Its name is formatted when printed.
    forces: Vec<(Entity, u8)>,
}

impl Names {
    /// Names for `world`, whose bodies are `bodies` (`(name, entity)` in file order). Force
    /// generators were spawned in file order after the bodies, so their entity order is the
    /// file order.
    pub(crate) fn new(world: &mut World, bodies: &[(String, Entity)]) -> Self {
        let mut text = String::with_capacity(bodies.iter().map(|(name, _)| name.len()).sum());
        let mut spans = Vec::with_capacity(bodies.len());
        for (name, e) in bodies {
            // Scene names are at most a few hundred bytes; a library world of more than 4 GB
            // of names gets the last ones by entity id.
            let Ok(start) = u32::try_from(text.len()) else {
                break;
            };
            text.push_str(name);
            let Ok(end) = u32::try_from(text.len()) else {
                break;
            };
            spans.push((*e, start, end));
        }
        spans.sort_unstable_by_key(|&(e, _, _)| e);
        let mut forces: Vec<(Entity, u8)> = world
            .query::<(Entity, Has<Spring>, Has<ConstantForce>, Has<ConstantTorque>)>()
            .iter(world)
            .filter_map(|(e, spring, force, torque)| match (spring, force, torque) {
                (true, _, _) => Some((e, 0)),
                (_, true, _) => Some((e, 1)),
                (_, _, true) => Some((e, 2)),
                _ => None,
            })
            .collect();
        forces.sort_unstable_by_key(|(e, _)| e.index());
        Self {
            bodies: spans,
            text,
            forces,
        }
    }

    /// The name of `entity`, or its id when it is not part of the scene.
    pub(crate) fn of(&self, entity: Entity) -> String {
        if let Ok(i) = self.bodies.binary_search_by_key(&entity, |&(e, _, _)| e) {
            let (_, start, end) = self.bodies[i];
            return format!(
                "body `{}`",
                terminal_safe(&self.text[start as usize..end as usize])
            );
        }
        match self
            .forces
            .binary_search_by_key(&entity.index(), |(e, _)| e.index())
        {
            Ok(index) if self.forces[index].0 == entity => {
                let kind = FORCE_KINDS[usize::from(self.forces[index].1)];
                format!("forces[{index}] ({kind})")
            }
            Ok(_) => format!("entity {entity}"),
            Err(_) => format!("entity {entity}"),
        }
    }
}

/// A planning-time warning, naming the body or spring as the scene does.
pub(crate) fn warning_line(warning: &StabilityWarning, names: &Names) -> String {
    let subject = warning.subject();
    let text = warning.to_string();
    // `Display` starts with the entity ("spring 12v0: …"); say the scene's name instead.
    let detail = text.split_once(": ").map_or(text.as_str(), |(_, d)| d);
    format!("{}: {detail}", names.of(subject))
}

/// A quarantined body: which, when, why, and the last valid state it keeps.
pub(crate) fn quarantine_line(
    error: &BodyError,
    step: u64,
    world: &World,
    names: &Names,
) -> String {
    let kept = match (
        world.get::<Pose>(error.entity),
        world.get::<Velocity>(error.entity),
    ) {
        (Some(t), Some(v)) => format!(
            "; it keeps its last valid state: position {}, rotation {}, velocity {}, angular \
             velocity {}",
            vector(t.translation),
            quaternion(t.rotation.to_array()),
            vector(v.linear),
            vector(v.angular)
        ),
        _ => String::new(),
    };
    // The error's own text starts with the entity id; the kind alone says why.
    format!(
        "{} quarantined at step {step}: {}{kept}",
        names.of(error.entity),
        error.kind
    )
}

fn vector(v: Vec3) -> String {
    format!("[{:.6e}, {:.6e}, {:.6e}]", v.x, v.y, v.z)
}

fn quaternion(q: [tumble_core::math::Real; 4]) -> String {
    format!("[{:.6}, {:.6}, {:.6}, {:.6}]", q[0], q[1], q[2], q[3])
}

/// Total mechanical energy (J, f64): kinetic `Σ ½m|v|² + ½ωᵀIω`, elastic `Σ ½k(|d| − L₀)²` of
/// the springs, and gravitational `−Σ m s g·x` (centre of mass; zero at the origin), and the
/// total angular momentum about the origin `Σ (x × m v + I ω)`.
pub(crate) fn totals(world: &mut World) -> (f64, DVec3) {
    let g = world
        .get_resource::<Gravity>()
        .map_or(DVec3::ZERO, |g| g.0.widen());
    let mut bodies = world.query_filtered::<(
        &Pose,
        &Velocity,
        &MassProps,
        Option<&GravityScale>,
        Has<Static>,
        Has<Kinematic>,
    ), With<RigidBody>>();
    let (mut energy, mut momentum) = (0.0, DVec3::ZERO);
    for (t, v, m, scale, fixed, kinematic) in bodies.iter(world) {
        if fixed || kinematic {
            continue;
        }
        let mass = m.mass().widen();
        let x = t.center_of_mass(m).widen();
        let lin = v.linear.widen();
        let spin = m.world_inertia_mul(t.rotation, v.angular).widen();
        energy += kinetic_energy_f64(t, v, m);
        energy -= mass * scale.map_or(1.0, |s| s.0.widen()) * g.dot(x);
        momentum += x.cross(mass * lin) + spin;
    }
    // Read in place: a copy of every spring would cost a large scene its size again.
    let mut springs = world.query::<&Spring>();
    let world: &World = world;
    for s in springs.iter(world) {
        let point = |e: Entity, local: Vec3| world.get::<Pose>(e).map(|t| t.transform_point(local));
        let pb = match s.b {
            SpringEnd::World(p) => Some(p),
            SpringEnd::Body { body, anchor } => point(body, anchor),
        };
        if let (Some(pa), Some(pb)) = (point(s.a, s.anchor_a), pb) {
            energy += s.elastic_energy(pa, pb);
        }
    }
    (energy, momentum)
}

/// Which totals a world conserves, and why not where it does not.
pub(crate) struct Conserved {
    /// `None` when the mechanical energy is conserved, else what changes it.
    pub energy: Option<&'static str>,
    /// `None` when the angular momentum about the origin is conserved, else what changes it.
    pub momentum: Option<&'static str>,
}

/// What the world's contents allow: damping (of bodies or springs) removes energy, constant
/// forces and torques do work; gravity keeps the energy (it is counted) but turns the momentum,
/// as do springs to fixed points and constant loads.
pub(crate) fn conserved(world: &mut World) -> Conserved {
    let damped_bodies = world
        .query::<&Damping>()
        .iter(world)
        .any(|d| d.linear != 0.0 || d.angular != 0.0);
    let springs: Vec<Spring> = world.query::<&Spring>().iter(world).copied().collect();
    let damped_springs = springs.iter().any(|s| s.damping != 0.0);
    let fixed = |world: &World, e: Entity| {
        world.get::<Static>(e).is_some() || world.get::<Kinematic>(e).is_some()
    };
    let anchored = springs.iter().any(|s| match s.b {
        SpringEnd::World(_) => true,
        SpringEnd::Body { body, .. } => fixed(world, body) || fixed(world, s.a),
    });
    let loads = world.query::<&ConstantForce>().iter(world).next().is_some()
        || world
            .query::<&ConstantTorque>()
            .iter(world)
            .next()
            .is_some();
    let gravity = world
        .get_resource::<Gravity>()
        .is_some_and(|g| g.0 != Vec3::ZERO);
    let energy = if damped_bodies || damped_springs {
        Some("damping removes energy")
    } else if loads {
        Some("constant forces and torques do work")
    } else {
        None
    };
    let momentum = if damped_bodies {
        Some("damping")
    } else if loads {
        Some("constant forces and torques")
    } else if gravity {
        Some("gravity")
    } else if anchored {
        Some("springs to fixed points")
    } else {
        None
    };
    Conserved { energy, momentum }
}

/// `after` against `before` in words: the relative drift, or the absolute change from zero.
/// Never prints NaN or infinity without saying why.
pub(crate) fn drift(before: f64, after: f64, unit: &str) -> String {
    if !(before.is_finite() && after.is_finite()) {
        return format!("not finite ({before:e} → {after:e} {unit}): a body's state overflowed");
    }
    if before == 0.0 {
        format!(
            "{after:.6e} {unit} from 0 (absolute change {:.3e})",
            after - before
        )
    } else {
        // Relative to |before|: a total that includes gravity's potential may be negative.
        format!(
            "{before:.6e} → {after:.6e} {unit}, relative drift {:.3e}",
            (after - before) / before.abs()
        )
    }
}
