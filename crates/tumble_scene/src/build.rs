//! A validated scene, and the world built from it.

use std::collections::HashMap;
use tumble_core::math::{Real, Vec3};

use bevy_ecs::prelude::*;

use tumble_core::{Integrator, MassProperties};
use tumble_ecs::components::ImplicitSpring;
use tumble_ecs::prelude::*;
use tumble_ecs::springs::{Classification, ClassifiedSpring, classify};

use crate::error::{SaveError, SceneError};
use crate::format::{SceneFile, WorldDef};
use crate::json::JsonSource;
use crate::spawn::{BodyKind, batch, runs, spawn_in_runs};
use crate::text::terminal_safe;
use crate::validate::{Checker, Locate, NoText, TomlText};

use crate::checks::{
    bad_name, bad_text, checked_body, checked_extras, checked_force, compose_names, validate_body,
    validate_forces, validate_world,
};
use crate::model::{SceneForce, ValidBody};
use crate::validate::{unknown_name, wrong_length};

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

/// The dotted path of the table a missing field is missing from (`toml` for the top level),
/// by a parse that tracks the path; `None` if that parse does not fail the same way.
fn missing_field_table(text: &str) -> Option<String> {
    let de = toml::Deserializer::parse(text).ok()?;
    let err = serde_path_to_error::deserialize::<_, SceneFile>(de).err()?;
    if !err.inner().message().starts_with("missing field") {
        return None;
    }
    let path = err.path().to_string();
    Some(if path.is_empty() || path == "." {
        "toml".to_owned()
    } else {
        path
    })
}

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
            // A missing field is reported with the span of the table that lacks it, which
            // for the top level is the whole file: no key holds it, and the first key at its
            // start (`[world]`) is not the one to blame. The table's path comes from a second
            // parse that tracks it, on this error path only.
            let field = if e.message().starts_with("missing field") {
                missing_field_table(text).unwrap_or(field)
            } else {
                field
            };
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
        // Checked here and converted again where the world is built, like the bodies: a file
        // of springs is held once, as read.
        validate_forces(&ck, &parsed.forces, &names)?;
        Ok(Self {
            file: parsed,
            settings: world.settings,
            steps: world.steps,
            gravity: world.gravity,
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

    /// Number of steps, `1..=`[`MAX_STEPS`](crate::MAX_STEPS).
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

    /// The force generators, in file order, as checked (converted from the file model, which
    /// the scene holds alone).
    pub fn forces(&self) -> Vec<SceneForce> {
        let names = self.names();
        self.scene_forces(&names).collect()
    }

    /// Each body's index by name, borrowed from the file model (the names the checks found
    /// the forces' bodies by).
    fn names(&self) -> HashMap<&str, usize> {
        (self.file.bodies.iter().enumerate())
            .map(|(i, b)| (b.name.as_str(), i))
            .collect()
    }

    /// The force generators in engine form, in file order, converted from the file model as
    /// they were checked, their bodies found in `names`.
    fn scene_forces<'s>(
        &'s self,
        names: &'s HashMap<&'s str, usize>,
    ) -> impl Iterator<Item = SceneForce> + Clone + 's {
        let ck = Checker {
            file: &self.file.name,
            locate: &NoText,
        };
        (self.file.forces.iter().enumerate())
            .map(move |(i, f)| checked_force(&ck, i, f, names).expect(CHECKED))
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
        let names = self.names();
        let loaded = self.loaded_bodies(self.scene_forces(&names));
        let classified = self.classification(self.scene_forces(&names));
        let kinds = self.body_kinds(&loaded, &classified);
        let file = &self.file.name;
        let bodies = spawn_in_runs(&mut world, &kinds, &loaded, &classified, |i| {
            let def = &self.file.bodies[i];
            (def.name.clone(), checked_body(file, i, def))
        });
        let kinds = force_runs(self.scene_forces(&names), &classified.implicit_springs);
        let mut forces = self.scene_forces(&names);
        spawn_forces(&mut world, &bodies, &kinds, || {
            forces.next().expect("one kind per force")
        });
        planned(world, bodies)
    }

    /// [`build`](Self::build), consuming the scene as the world fills: each body's file model
    /// is released once it is spawned, so memory peaks at about the larger of the two, not
    /// their sum (a million bodies: ≈ 250 MB of file model, ≈ 200 MB of world).
    pub fn into_built(mut self) -> BuiltScene {
        let mut world = self.world_for_bodies();
        // What the spawns need of the forces, from one pass each over the file model.
        let names = self.names();
        let loaded = self.loaded_bodies(self.scene_forces(&names));
        let classified = self.classification(self.scene_forces(&names));
        let force_kinds = force_runs(self.scene_forces(&names), &classified.implicit_springs);
        drop(names);
        let kinds = self.body_kinds(&loaded, &classified);
        let mut defs = std::mem::take(&mut self.file.bodies);
        let n = defs.len();
        // Popped from the back in file order; the vector is shrunk as it empties, which hands
        // its pages back (a large allocation is shrunk in place).
        defs.reverse();
        let release_every = (n / 8).max(1 << 16);
        let file = &self.file.name;
        let bodies = spawn_in_runs(&mut world, &kinds, &loaded, &classified, |i| {
            let def = defs.pop().expect("one definition per body");
            let body = checked_body(file, i, &def);
            if (i + 1) % release_every == 0 {
                defs.shrink_to_fit();
            }
            (def.name, body)
        });
        drop((defs, classified));
        // The forces the same way: converted from the file model as their generators spawn,
        // and released, so that a file of springs is never held twice. Their bodies are found
        // by the names the spawned bodies took along (the same indices: file order).
        let mut forces = std::mem::take(&mut self.file.forces);
        let file = std::mem::take(&mut self.file.name);
        drop(self);
        let names: HashMap<&str, usize> = (bodies.iter().enumerate())
            .map(|(i, (name, _))| (name.as_str(), i))
            .collect();
        let ck = Checker {
            file: &file,
            locate: &NoText,
        };
        forces.reverse();
        let release_every = (forces.len() / 8).max(1 << 16);
        let mut spawned = 0;
        spawn_forces(&mut world, &bodies, &force_kinds, || {
            let def = forces.pop().expect("one kind per force");
            spawned += 1;
            if spawned % release_every == 0 {
                forces.shrink_to_fit();
            }
            checked_force(&ck, spawned - 1, &def, &names).expect(CHECKED)
        });
        drop((forces, names, force_kinds));
        // Planning builds tables of its own (the springs' classification, the audit's) with
        // only the world and the names held.
        planned(world, bodies)
    }

    /// Per body, whether a force generator names it. Such a body is spawned with its
    /// [`ForceAccumulator`] (which the generator's hook would otherwise add): adding a component
    /// moves the body to another table, and the table it leaves keeps its memory, so a world
    /// whose bodies all get one would hold them twice.
    fn loaded_bodies(&self, forces: impl Iterator<Item = SceneForce>) -> Vec<bool> {
        let mut loaded = vec![false; self.file.bodies.len()];
        for f in forces {
            match f {
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

    /// Per body, the optional components it is spawned with (see [`crate::spawn`]), from the
    /// two fields that decide them (not the whole check of each body).
    fn body_kinds(&self, loaded: &[bool], classified: &Classification) -> Vec<BodyKind> {
        (self.file.bodies.iter().enumerate())
            .map(|(i, def)| {
                BodyKind::new(
                    loaded[i],
                    checked_extras(&self.file.name, i, def),
                    classified.turns.get(i).copied().flatten(),
                    classified.implicit_bodies.get(i).copied().unwrap_or(false),
                )
            })
            .collect()
    }

    /// The spring classification of the scene's world (see
    /// [`tumble_ecs::springs::classify`]), so that its bodies and springs are spawned with the
    /// markers it gives them; empty when the scene has no springs.
    fn classification(&self, forces: impl Iterator<Item = SceneForce> + Clone) -> Classification {
        let springs = forces.filter_map(|f| match f {
            SceneForce::Spring {
                a,
                anchor_a,
                b,
                anchor_b,
                k,
                ..
            } => Some(ClassifiedSpring {
                a: Some(a),
                anchor_a,
                b,
                anchor_b,
                stiffness: k,
            }),
            _ => None,
        });
        if springs.clone().next().is_none() {
            return Classification::default();
        }
        let masses: Vec<MassProps> = self.valid_bodies().map(|b| MassProps(b.mass)).collect();
        classify(&self.settings, &masses, springs)
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
}

/// The runs of one kind `forces` are spawned in (see [`spawn_forces`]), springs of one solve
/// by `implicit_springs` (per spring).
fn force_runs(
    forces: impl Iterator<Item = SceneForce>,
    implicit_springs: &[bool],
) -> Vec<ForceRun> {
    let mut spring = 0;
    forces
        .map(|f| match f {
            SceneForce::Constant { .. } => ForceRun::Constant,
            SceneForce::Torque { .. } => ForceRun::Torque,
            SceneForce::Spring { .. } => {
                spring += 1;
                ForceRun::Spring {
                    implicit: implicit_springs.get(spring - 1).copied().unwrap_or(false),
                }
            }
        })
        .collect()
}

/// Conversions of what the scene's checks accepted cannot fail.
const CHECKED: &str = "checked when the scene was parsed";

/// The kind of a run of forces spawned by one batch: one generator type, and for springs one
/// solve (the classification's, so that no spring moves to another table when it is planned).
/// A byte a force, beside the forces themselves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum ForceRun {
    Constant,
    Torque,
    Spring { implicit: bool },
}

/// Spawns the force generators between the spawned `bodies`, in runs of one kind (`kinds`, per
/// force); `next()` gives the forces in scene order, once each.
fn spawn_forces(
    world: &mut World,
    bodies: &[(String, Entity)],
    kinds: &[ForceRun],
    mut next: impl FnMut() -> SceneForce,
) {
    let entity = |i: usize| bodies[i].1;
    const ONE_KIND: &str = "a run holds one kind of force";
    for (start, len) in runs(kinds) {
        let run = (0..len).map(|_| next());
        match kinds[start] {
            ForceRun::Constant => {
                let run = run.map(|f| match f {
                    SceneForce::Constant { body, force, point } => ConstantForce {
                        body: entity(body),
                        force,
                        local_point: point,
                    },
                    _ => unreachable!("{ONE_KIND}"),
                });
                batch(world, run, drop);
            }
            ForceRun::Torque => {
                let run = run.map(|f| match f {
                    SceneForce::Torque { body, torque } => ConstantTorque {
                        body: entity(body),
                        torque,
                    },
                    _ => unreachable!("{ONE_KIND}"),
                });
                batch(world, run, drop);
            }
            ForceRun::Spring { implicit: true } => {
                let run = run.map(|f| (spring_of(f, &entity), ImplicitSpring));
                batch(world, run, drop);
            }
            ForceRun::Spring { implicit: false } => {
                batch(world, run.map(|f| spring_of(f, &entity)), drop);
            }
        }
    }
}

/// The spring generator of the scene's spring `f`, its bodies' entities given by `entity`.
fn spring_of(f: SceneForce, entity: &impl Fn(usize) -> Entity) -> Spring {
    match f {
        SceneForce::Spring {
            a,
            anchor_a,
            b,
            anchor_b,
            k,
            c,
            rest,
        } => Spring {
            a: entity(a),
            anchor_a,
            b: match b {
                Some(b) => SpringEnd::Body {
                    body: entity(b),
                    anchor: anchor_b,
                },
                None => SpringEnd::World(anchor_b),
            },
            stiffness: k,
            damping: c,
            rest_length: rest,
        },
        _ => unreachable!("a run holds one kind of force"),
    }
}

/// The built scene of a world whose bodies and forces are spawned: its schedule planned.
fn planned(mut world: World, bodies: Vec<(String, Entity)>) -> BuiltScene {
    let physics = PhysicsRunner::new(&mut world);
    BuiltScene {
        world,
        physics,
        bodies,
    }
}

impl BuiltScene {
    /// Advances the world by one step (the schedule once per stage, re-planned first if the
    /// world changed) and clears its change trackers.
    pub fn step(&mut self) {
        self.physics.step(&mut self.world);
        self.world.clear_trackers();
    }
}
