//! A validated scene, and the world built from it.

use std::borrow::Cow;
use std::collections::HashMap;
use std::num::NonZeroU32;
use tumble_core::math::{Quat, REAL_NAME, Real, Vec3, quat_normalize};

use bevy_ecs::prelude::*;

use tumble_core::shapes::parry::shape::{Ball, Capsule, Cone, Cuboid, Cylinder};
use tumble_core::shapes::{HullError, convex_hull_mass_properties, mass_properties_of};
use tumble_core::{Density, Integrator, Mass, MassProperties};
use tumble_ecs::prelude::*;

use crate::error::{SaveError, SceneError};
use crate::format::{BodyDef, ForceDef, SceneFile, ShapeDef, WorldDef};
use crate::json::JsonSource;
use crate::text::{is_unsafe_char, terminal_safe};
use crate::validate::{Checker, Locate, NoText, TomlText};
use tumble_core::error::compact;

/// A scene that passed every check: it builds a world without failing.
///
/// Its parts are read through accessors and cannot be changed in place, so a `Scene` always
/// holds what its checks accepted (no NaN step, no unknown body). To change a scene, change its
/// [`SceneFile`] and parse the result again (`to_toml` then [`Scene::parse`]), which checks it
/// like a file.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    file: SceneFile,
    settings: PhysicsSettings,
    steps: u64,
    gravity: Option<Vec3>,
    forces: Vec<SceneForce>,
}

/// One body of a [`Scene`], as the engine will start it.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneBody {
    /// Its name (unique in the scene).
    pub name: String,
    /// Mass properties.
    pub mass: MassProperties,
    /// Initial state, with the centre-of-mass position.
    pub state: tumble_core::BodyState,
    /// Gravity scale.
    pub gravity_scale: Real,
    /// Linear damping `c_lin` (1/s) of the body's `Damping`.
    pub linear_damping: Real,
    /// Angular damping `c_ang` (1/s) of the body's `Damping`.
    pub angular_damping: Real,
}

#[derive(Debug, Clone, PartialEq)]
struct ValidBody {
    mass: MassProperties,
    transform: Pose,
    velocity: Velocity,
    gravity_scale: Real,
    damping: Damping,
}

/// A force generator of a [`Scene`] as its checks accepted it: bodies by their index in file
/// order ([`Scene::body_states`]), vectors and numbers in the engine precision.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SceneForce {
    /// A constant force on `body`, at its centre of mass or at `point` (body frame).
    Constant {
        /// The body's index.
        body: usize,
        /// The force (N), world frame.
        force: Vec3,
        /// Where it acts, body coordinates relative to the origin; `None`: the centre of mass.
        point: Option<Vec3>,
    },
    /// A constant torque on `body`.
    Torque {
        /// The body's index.
        body: usize,
        /// The torque (N·m), world frame.
        torque: Vec3,
    },
    /// A spring from `anchor_a` on body `a` to `anchor_b` on body `b` (body coordinates), or to
    /// the world point `anchor_b` when `b` is `None`.
    Spring {
        /// The first body's index.
        a: usize,
        /// The anchor on `a`.
        anchor_a: Vec3,
        /// The other body's index, or `None` for a world point.
        b: Option<usize>,
        /// The anchor on `b`, or the world point.
        anchor_b: Vec3,
        /// Stiffness (N/m), `>= 0`.
        k: Real,
        /// Damping (N·s/m), `>= 0`.
        c: Real,
        /// Rest length (m), `>= 0`.
        rest: Real,
    },
}

/// A world built from a scene, with its planned schedule and the bodies in file order.
pub struct BuiltScene {
    /// The world.
    pub world: World,
    /// The step of the world, planned from it and re-planned when it changes (step with
    /// [`step`](Self::step)).
    pub physics: PhysicsRunner,
    /// `(name, entity)` of every body, in file order.
    pub bodies: Vec<(String, Entity)>,
}

/// The syntax of a scene file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SceneSyntax {
    /// TOML (`DESIGN.md`'s format; the default).
    Toml,
    /// JSON with the same schema: for large scenes, read as a stream (see
    /// [`load_scene`](crate::load_scene)).
    Json,
}

impl SceneSyntax {
    /// JSON for a path ending in `.json` (any case), TOML otherwise.
    pub fn of(path: &std::path::Path) -> Self {
        match path.extension() {
            Some(ext) if ext.eq_ignore_ascii_case("json") => Self::Json,
            _ => Self::Toml,
        }
    }
}

/// Largest accepted step count.
pub const MAX_STEPS: u64 = 1_000_000_000;

/// Most substeps per step a scene may ask for: each costs a whole step, so beyond this a smaller
/// `dt` is the honest setting.
pub const MAX_SUBSTEPS: u32 = 1000;

impl Scene {
    /// Parses and validates scene text; `file` names it in errors.
    pub fn parse(file: &str, text: &str) -> Result<Self, SceneError> {
        let parsed: SceneFile = toml::from_str(text).map_err(|e| {
            let mut start = e.span().map_or(0, |s| s.start.min(text.len()));
            if let (Some(span), Some(got)) = (e.span(), wrong_length(e.message())) {
                // Inside a tagged table toml points at the table: find the array itself.
                if let Some(at) = crate::validate::array_of_len_after(text, span.start, got) {
                    start = at;
                }
            }
            if let (Some(span), Some(key)) = (e.span(), unknown_name(e.message())) {
                // Likewise for an unknown key or variant in a tagged table.
                if let Some(at) = crate::validate::key_after(text, span.start, key) {
                    start = at;
                }
            }
            let line = match e.span() {
                Some(_) => crate::validate::line_at(text, start),
                // The reader gives no position for a key path nested too deep: find it.
                None if e.message().contains("recursion") => {
                    let line = crate::validate::line_of_longest_key(text);
                    let message = format!(
                        "{}: a key nested deeper than the TOML reader allows; expected the keys \
                         of a scene file",
                        e.message().replace('\n', " ")
                    );
                    return SceneError::at(file, line, "toml", message);
                }
                None => crate::validate::line_at(text, start),
            };
            let message = e.message().replace('\n', " ");
            // The field is the key path at the error, when the text parses as TOML at all;
            // otherwise (a syntax error) the key on the offending line, when there is one.
            let field = crate::validate::path_at(text, start)
                .or_else(|| {
                    text.lines()
                        .nth(line - 1)
                        .and_then(|l| l.split_once('=').map(|(k, _)| k.trim().to_owned()))
                        .filter(|k| !k.is_empty() && !k.starts_with('['))
                })
                .unwrap_or_else(|| "toml".to_owned());
            SceneError::at(file, line, field, message)
        })?;
        Self::validate(file, &TomlText(text), parsed)
    }

    /// Parses and validates scene text in JSON (the schema of the TOML files, e.g.
    /// `{"name": …, "world": {…}, "bodies": [{…}], "forces": [{"type": "spring", …}]}`);
    /// `file` names it in errors.
    pub fn parse_json(file: &str, text: &str) -> Result<Self, SceneError> {
        let source = JsonSource::Text(text.as_bytes());
        let parsed = crate::json::parse(file, text.as_bytes(), source)?;
        Self::validate(file, &source, parsed)
    }

    /// Parses and validates JSON read from `input` as a stream, without holding its text;
    /// `source` is read again only to locate an error.
    pub(crate) fn read_json(
        file: &str,
        input: impl std::io::BufRead,
        source: JsonSource<'_>,
    ) -> Result<Self, SceneError> {
        let parsed = crate::json::parse(file, input, source)?;
        Self::validate(file, &source, parsed)
    }

    /// The same scene with other world settings (`dt`, `steps`, integrator, springs,
    /// substeps, gravity), checked like a file's; the bodies and forces are kept as they were
    /// checked. Errors name the field and no line: the settings did not come from the file.
    pub fn with_world(mut self, world: WorldDef) -> Result<Self, SceneError> {
        let file = self.file.name.clone();
        let ck = Checker {
            file: &file,
            locate: &NoText,
        };
        let checked = validate_world(&ck, &world)?;
        self.settings = checked.settings;
        self.steps = checked.steps;
        self.gravity = checked.gravity;
        self.file.world = world;
        Ok(self)
    }

    fn validate(
        file: &str,
        locate: &dyn Locate,
        mut parsed: SceneFile,
    ) -> Result<Self, SceneError> {
        compose_names(&mut parsed);
        let ck = Checker { file, locate };
        let world = validate_world(&ck, &parsed.world)?;
        if let Some(why) = bad_text(&parsed.name) {
            return Err(ck.top_error("name", why));
        }
        // Names are borrowed from the model: a scene of a million bodies holds them once.
        let mut names: HashMap<&str, usize> = HashMap::with_capacity(parsed.bodies.len());
        for (i, b) in parsed.bodies.iter().enumerate() {
            if let Some(why) = bad_name(&b.name) {
                return Err(ck.error("bodies", Some(i), "name", why));
            }
            if names.insert(&b.name, i).is_some() {
                return Err(ck.error(
                    "bodies",
                    Some(i),
                    "name",
                    format!("duplicate body name `{}`", terminal_safe(&b.name)),
                ));
            }
            // Checked here, converted again when the world is built: a scene holds its file
            // model once, not a second, engine-ready copy of every body.
            validate_body(&ck, i, b)?;
        }
        let forces = validate_forces(&ck, &parsed.forces, &names)?;
        Ok(Self {
            file: parsed,
            settings: world.settings,
            steps: world.steps,
            gravity: world.gravity,
            forces,
        })
    }

    /// The file model, as read (for saving, or to derive a changed scene from).
    pub fn file(&self) -> &SceneFile {
        &self.file
    }

    /// The scene name.
    pub fn name(&self) -> &str {
        &self.file.name
    }

    /// Time step (s): finite and `> 0` in the build precision.
    pub fn dt(&self) -> Real {
        self.settings.dt()
    }

    /// Step and integrator, as the world will get them.
    pub fn settings(&self) -> PhysicsSettings {
        self.settings
    }

    /// Number of steps, `1..=`[`MAX_STEPS`].
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// The integrator.
    pub fn integrator(&self) -> Integrator {
        self.settings.integrator
    }

    /// Uniform gravity, if the scene has any.
    pub fn gravity(&self) -> Option<Vec3> {
        self.gravity
    }

    /// The force generators, in file order, as checked.
    pub fn forces(&self) -> &[SceneForce] {
        &self.forces
    }

    /// Each body with its mass properties, initial state and per-body parameters, in file
    /// order.
    pub fn body_states(&self) -> Vec<SceneBody> {
        self.valid_bodies()
            .zip(&self.file.bodies)
            .map(|(b, def)| {
                let props = MassProps(b.mass);
                SceneBody {
                    name: def.name.clone(),
                    mass: b.mass,
                    state: tumble_ecs::components::body_state(&b.transform, &b.velocity, &props),
                    gravity_scale: b.gravity_scale,
                    linear_damping: b.damping.linear,
                    angular_damping: b.damping.angular,
                }
            })
            .collect()
    }

    /// The bodies in engine form, converted from the file model as they were when checked.
    fn valid_bodies(&self) -> impl Iterator<Item = ValidBody> + '_ {
        let file = &self.file.name;
        (self.file.bodies.iter().enumerate()).map(move |(i, b)| checked_body(file, i, b))
    }

    /// The scene as TOML (loading it gives the same scene).
    pub fn to_toml(&self) -> Result<String, SaveError> {
        crate::to_toml_string(&self.file)
    }

    /// Builds the world and plans its schedule. Cannot fail: everything was checked when the
    /// scene was parsed.
    pub fn build(&self) -> BuiltScene {
        let mut world = self.world_for_bodies();
        let loaded = self.loaded_bodies();
        let bodies = self
            .valid_bodies()
            .zip(&self.file.bodies)
            .zip(&loaded)
            .map(|((body, def), &loaded)| (def.name.clone(), spawn_body(&mut world, &body, loaded)))
            .collect();
        self.finish_build(world, bodies)
    }

    /// [`build`](Self::build), consuming the scene as the world fills: each body's file model
    /// is released once it is spawned, so memory peaks at about the larger of the two, not
    /// their sum (a million bodies: ≈ 250 MB of file model, ≈ 200 MB of world).
    pub fn into_built(mut self) -> BuiltScene {
        let mut world = self.world_for_bodies();
        let loaded = self.loaded_bodies();
        // The forces' file model (names as strings) is not needed once checked: `self.forces`
        // holds them by index. Dropped before the world grows.
        drop(std::mem::take(&mut self.file.forces));
        let mut defs = std::mem::take(&mut self.file.bodies);
        let n = defs.len();
        // Popped from the back in file order; the vector is shrunk as it empties, which hands
        // its pages back (a large allocation is shrunk in place).
        defs.reverse();
        let release_every = (n / 8).max(1 << 16);
        let mut bodies = Vec::with_capacity(n);
        let mut i = 0;
        while let Some(def) = defs.pop() {
            let body = checked_body(&self.file.name, i, &def);
            bodies.push((def.name, spawn_body(&mut world, &body, loaded[i])));
            i += 1;
            if i % release_every == 0 {
                defs.shrink_to_fit();
            }
        }
        drop(defs);
        self.finish_build(world, bodies)
    }

    /// Per body, whether a force generator names it. Such a body is spawned with its
    /// [`ForceAccumulator`] (which the generator's hook would otherwise add): adding a component
    /// moves the body to another table, and the table it leaves keeps its memory, so a world
    /// whose bodies all get one would hold them twice.
    fn loaded_bodies(&self) -> Vec<bool> {
        let mut loaded = vec![false; self.file.bodies.len()];
        for f in &self.forces {
            match *f {
                SceneForce::Constant { body, .. } | SceneForce::Torque { body, .. } => {
                    loaded[body] = true;
                }
                SceneForce::Spring { a, b, .. } => {
                    loaded[a] = true;
                    if let Some(b) = b {
                        loaded[b] = true;
                    }
                }
            }
        }
        loaded
    }

    /// A world with the scene's resources, ready for its bodies.
    fn world_for_bodies(&self) -> World {
        let mut world = World::new();
        world.insert_resource(self.settings);
        if let Some(g) = self.gravity {
            world.insert_resource(Gravity(g));
        }
        world
    }

    /// Spawns the force generators between the spawned `bodies` and plans the schedule.
    fn finish_build(&self, mut world: World, bodies: Vec<(String, Entity)>) -> BuiltScene {
        let entity = |i: usize| bodies[i].1;
        for f in &self.forces {
            match *f {
                SceneForce::Constant { body, force, point } => {
                    world.spawn(ConstantForce {
                        body: entity(body),
                        force,
                        local_point: point,
                    });
                }
                SceneForce::Torque { body, torque } => {
                    world.spawn(ConstantTorque {
                        body: entity(body),
                        torque,
                    });
                }
                SceneForce::Spring {
                    a,
                    anchor_a,
                    b,
                    anchor_b,
                    k,
                    c,
                    rest,
                } => {
                    let end = match b {
                        Some(b) => SpringEnd::Body {
                            body: entity(b),
                            anchor: anchor_b,
                        },
                        None => SpringEnd::World(anchor_b),
                    };
                    world.spawn(Spring {
                        a: entity(a),
                        anchor_a,
                        b: end,
                        stiffness: k,
                        damping: c,
                        rest_length: rest,
                    });
                }
            }
        }
        let physics = PhysicsRunner::new(&mut world);
        BuiltScene {
            world,
            physics,
            bodies,
        }
    }
}

/// Body `i` of a scene in engine form: [`validate_body`] again, which cannot fail on a body
/// that passed it when the scene was parsed (a `Scene`'s model is not changed in place).
fn checked_body(file: &str, i: usize, def: &BodyDef) -> ValidBody {
    let ck = Checker {
        file,
        locate: &NoText,
    };
    validate_body(&ck, i, def).unwrap_or_else(|e| {
        unreachable!("body {i} passed this check when the scene was parsed: {e}")
    })
}

/// Spawns one body with only the components it needs: a [`ForceAccumulator`] only when a force
/// generator will name it (`loaded`).
fn spawn_body(world: &mut World, b: &ValidBody, loaded: bool) -> Entity {
    let mut e = world.spawn((RigidBody, MassProps(b.mass), b.transform, b.velocity));
    if loaded {
        e.insert(ForceAccumulator::default());
    }
    if b.gravity_scale != 1.0 {
        e.insert(GravityScale(b.gravity_scale));
    }
    if b.damping != Damping::default() {
        e.insert(b.damping);
    }
    e.id()
}

impl BuiltScene {
    /// Advances the world by one step (the schedule once per stage, re-planned first if the
    /// world changed) and clears its change trackers.
    pub fn step(&mut self) {
        self.physics.step(&mut self.world);
        self.world.clear_trackers();
    }
}

/// The world settings of a scene, checked.
struct CheckedWorld {
    settings: PhysicsSettings,
    steps: u64,
    gravity: Option<Vec3>,
}

fn validate_world(ck: &Checker<'_>, w: &WorldDef) -> Result<CheckedWorld, SceneError> {
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

/// The force generators, their bodies looked up by name.
fn validate_forces(
    ck: &Checker<'_>,
    defs: &[ForceDef],
    names: &HashMap<&str, usize>,
) -> Result<Vec<SceneForce>, SceneError> {
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
    let mut forces = Vec::with_capacity(defs.len());
    for (i, f) in defs.iter().enumerate() {
        let v = |key: &str, x: [f64; 3]| ck.vec3("forces", Some(i), key, x);
        forces.push(match f {
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
                SceneForce::Spring {
                    a: a_index,
                    anchor_a: v("anchor_a", *anchor_a)?,
                    b: b_index,
                    anchor_b: v("anchor_b", *anchor_b)?,
                    k: non_negative("stiffness", *stiffness)?,
                    c: non_negative("damping", *damping)?,
                    rest: non_negative("rest_length", *rest_length)?,
                }
            }
        });
    }
    Ok(forces)
}

fn validate_body(ck: &Checker<'_>, i: usize, b: &BodyDef) -> Result<ValidBody, SceneError> {
    let t = "bodies";
    let mass = match (&b.mass, &b.inertia, &b.shape, &b.density) {
        (Some(m), Some(inertia), None, None) => {
            let m = ck.scalar(t, Some(i), "mass", *m)?;
            let mass = Mass::new(m).map_err(|e| ck.error(t, Some(i), "mass", e.to_string()))?;
            let inertia = ck.vec3(t, Some(i), "inertia", *inertia)?;
            MassProperties::new(mass, inertia)
                .map_err(|e| ck.error(t, Some(i), "inertia", e.to_string()))?
        }
        (None, None, Some(shape), Some(rho)) => {
            let rho = ck.scalar(t, Some(i), "density", *rho)?;
            let density =
                Density::new(rho).map_err(|e| ck.error(t, Some(i), "density", e.to_string()))?;
            shape_mass(ck, i, shape, density)?
        }
        _ => {
            return Err(ck.error(
                t,
                Some(i),
                "mass",
                "expected either `mass` and `inertia`, or `shape` and `density`",
            ));
        }
    };
    let position = ck.vec3(t, Some(i), "position", b.position)?;
    let r = b.rotation;
    let mut q = [0.0 as Real; 4];
    for (o, x) in q.iter_mut().zip(r) {
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
    let linear = ck.vec3(t, Some(i), "linear_velocity", b.linear_velocity)?;
    let angular = ck.vec3(t, Some(i), "angular_velocity", b.angular_velocity)?;
    // The engine computes ½m|v|² and ½ωᵀIω in its precision (energy reports, the divergence
    // check): both must be finite there, or the body is garbage from step 0.
    let overflow = |key: &str, what: &str, value: Real| {
        ck.error(
            t,
            Some(i),
            key,
            format!(
                "initial kinetic energy overflows {REAL_NAME} ({what} = {}); expected a smaller \
                 velocity",
                compact(value)
            ),
        )
    };
    let linear_energy = 0.5 * mass.mass() * linear.length_squared();
    if !linear_energy.is_finite() {
        return Err(overflow("linear_velocity", "½m|v|²", linear_energy));
    }
    let angular_energy = 0.5
        * mass
            .world_inertia_mul(quat_normalize(rotation), angular)
            .dot(angular);
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
    // A zero moment locks its axis and every integrator holds the rate about it at 0: a rate
    // given there would vanish in the first step, so a file's is refused rather than dropped
    // (the library's planner warns of it).
    let locked = mass.locked_axis_rates(quat_normalize(rotation), angular);
    if locked.length() > tumble_ecs::stability::LOCKED_RATE_LIMIT * angular.length() {
        let axes: Vec<&str> = ["x", "y", "z"]
            .into_iter()
            .zip(locked.to_array())
            .filter(|(_, rate)| *rate != 0.0)
            .map(|(axis, _)| axis)
            .collect();
        return Err(ck.error(
            t,
            Some(i),
            "angular_velocity",
            format!(
                "turns at {} rad/s about the locked principal axis {} (a zero moment of inertia                  holds the rate about its axis at 0); expected no rate about it",
                compact(locked.length()),
                axes.join(" and ")
            ),
        ));
    }
    let gravity_scale = ck.scalar(t, Some(i), "gravity_scale", b.gravity_scale)?;
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
    Ok(ValidBody {
        mass,
        transform: Pose {
            translation: position,
            // The engine's own normalization (in f64, rounded once), not glam's, whose SIMD and
            // scalar builds round differently: the same file gives the same bits in every build.
            rotation: quat_normalize(rotation),
        },
        velocity: Velocity { linear, angular },
        gravity_scale,
        damping,
    })
}

fn shape_mass(
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
    result.map_err(|e| mass_error(ck, i, e))
}

/// A shape whose mass properties are not valid.
fn mass_error(ck: &Checker<'_>, i: usize, e: tumble_core::InvalidInput) -> SceneError {
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

/// `k` from the messages "unknown field `k`, …" and "unknown variant `k`, …".
pub(crate) fn unknown_name(message: &str) -> Option<&str> {
    let rest = message
        .strip_prefix("unknown field `")
        .or_else(|| message.strip_prefix("unknown variant `"))?;
    rest.split_once('`').map(|(name, _)| name)
}

/// `M` from the message "expected N numbers, got M" of a fixed-length array.
pub(crate) fn wrong_length(message: &str) -> Option<usize> {
    let rest = message.split_once("numbers, got ")?.1;
    rest.trim().parse().ok()
}

/// Puts every name of the model (the scene's, the bodies', and those the forces refer to) in
/// Unicode normalization form C, so that one name typed composed (`é`, U+00E9) and decomposed
/// (`e` + U+0301) is one name: two bodies cannot differ by it alone, and a force finds its body
/// either way. Names already composed (almost all) are not copied.
fn compose_names(model: &mut SceneFile) {
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
fn prints_blank(c: char) -> bool {
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
fn bad_text(name: &str) -> Option<String> {
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
fn bad_name(name: &str) -> Option<String> {
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
