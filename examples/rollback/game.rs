//! A two-player game on a tumble world, driven by GGRS: each player pushes one end of a chain of
//! asymmetric bodies joined by springs at off-centre anchors (one pair stiff enough for the
//! implicit spring step), under gravity, with damping and a thruster whose force the input sets.
//! Shared by the `rollback` example and the GGRS test (`tests/rollback.rs`).

use ggrs::{Config, GgrsError, GgrsRequest, InputStatus, PlayerType, SessionBuilder};
use tumble::bevy_ecs::prelude::*;
use tumble::math::{Quat, Real, Vec3};
use tumble::prelude::*;

/// The GGRS types of the game: one byte of buttons per player per frame.
pub(super) struct GameConfig;

impl Config for GameConfig {
    type Input = u8;
    type InputPredictor = ggrs::PredictRepeatLast;
    type State = RollbackSnapshot;
    type Address = ();
}

/// The world, its runner and the entities the inputs act on.
pub(super) struct Game {
    /// The physics world.
    pub world: World,
    runner: PhysicsRunner,
    /// The body each player pushes.
    players: [Entity; 2],
    /// Each player's thruster (a force at a body point, set from the input).
    thrusters: [Entity; 2],
    /// Frames advanced, counting resimulated ones.
    pub advanced: u64,
    /// States loaded (rollbacks).
    pub loaded: u64,
}

/// Player `player`'s buttons at `frame`: a fixed pseudo-random pattern that changes every few
/// frames, so that the forces vary.
pub(super) fn buttons(player: usize, frame: i32) -> u8 {
    let x = (frame as u32 / 5)
        .wrapping_mul(0x9E37_79B9)
        .wrapping_add(player as u32 * 0x85EB_CA6B);
    ((x ^ (x >> 15)) >> 7) as u8
}

impl Game {
    /// Ten bodies in a chain at 60 Hz with the given integrator.
    pub(super) fn new(integrator: Integrator) -> Self {
        let mut world = World::new();
        world.insert_resource(PhysicsSettings::new(1.0 / 60.0, integrator).expect("60 Hz"));
        world.insert_resource(Gravity(Vec3::new(0.0, -9.81, 0.0)));
        let mut bodies = Vec::new();
        for i in 0..10u32 {
            let f = i as Real;
            let inertia = [[0.02, 0.03, 0.04], [0.01, 0.5, 0.51], [0.2, 0.3, 0.35]][i as usize % 3];
            let mass =
                MassProperties::new(Mass::new(1.0 + 0.1 * f).expect("mass > 0"), inertia.into())
                    .expect("valid inertia");
            let pose = Pose::new(Vec3::new(f, 0.0, 0.0), Quat::from_rotation_z(0.2 * f));
            let spin = Velocity::angular(Vec3::new(0.5, 1.0 + 0.3 * f, -0.2));
            let mut body = world.spawn((
                RigidBody,
                MassProps(mass),
                pose,
                spin,
                ForceAccumulator::default(),
            ));
            if i % 4 == 1 {
                body.insert(Damping {
                    linear: 0.2,
                    angular: 0.1,
                });
            }
            bodies.push(body.id());
        }
        for (i, pair) in bodies.windows(2).enumerate() {
            // One stiff pair (ωΔt ≈ 5 there): the plan steps it with the implicit solve.
            let stiffness = if i == 4 { 9.0e4 } else { 60.0 };
            let damping = if i % 3 == 0 { 0.2 } else { 0.0 };
            let next = SpringEnd::on_body(pair[1], Vec3::new(-0.3, 0.0, 0.1));
            let spring = Spring::new(pair[0], Vec3::new(0.3, 0.1, 0.0), next, stiffness, 0.5);
            world.spawn(spring.with_damping(damping));
        }
        let hook = SpringEnd::World(Vec3::new(0.0, 2.0, 0.0));
        world.spawn(Spring::new(bodies[0], Vec3::ZERO, hook, 80.0, 1.0));
        let players = [bodies[0], bodies[9]];
        let thrusters = players.map(|body| {
            world
                .spawn(ConstantForce {
                    body,
                    force: Vec3::ZERO,
                    local_point: Some(Vec3::new(0.0, 0.2, 0.1)),
                })
                .id()
        });
        let runner = PhysicsRunner::new(&mut world);
        Self {
            world,
            runner,
            players,
            thrusters,
            advanced: 0,
            loaded: 0,
        }
    }

    /// One frame with these inputs: bits 0–2 push the player's body along ±x, +y, ±z (through
    /// its accumulator, held over the step), bits 3–5 set its thruster, bit 6 twists it.
    pub(super) fn advance(&mut self, inputs: &[u8]) {
        for (player, &bits) in inputs.iter().enumerate() {
            let on = |bit: u8| if bits & (1 << bit) != 0 { 1.0 } else { 0.0 };
            let push = Vec3::new(on(0) - on(2) * 0.5, 3.0 * on(1), on(2) - 0.5 * on(0));
            let mut acc = self
                .world
                .get_mut::<ForceAccumulator>(self.players[player])
                .expect("the player's body has an accumulator");
            acc.add_force(4.0 * push);
            acc.add_torque(Vec3::new(0.0, 0.5 * on(6), 0.0));
            let mut thruster = self
                .world
                .get_mut::<ConstantForce>(self.thrusters[player])
                .expect("the player's thruster");
            thruster.force = Vec3::new(2.0 * on(3), 5.0 * on(4), -2.0 * on(5));
        }
        self.runner.step(&mut self.world);
        self.world.clear_trackers();
        self.advanced += 1;
    }

    /// Fulfils GGRS's requests in order: save (a snapshot and the world checksum), load
    /// (restore in place) and advance.
    pub(super) fn handle(&mut self, requests: Vec<GgrsRequest<GameConfig>>) {
        for request in requests {
            match request {
                GgrsRequest::SaveGameState { cell, frame } => {
                    let snapshot = RollbackSnapshot::capture(&mut self.world);
                    cell.save(frame, Some(snapshot), Some(world_checksum(&self.world).0));
                }
                GgrsRequest::LoadGameState { cell, .. } => {
                    let snapshot = cell.load().expect("GGRS loads only saved frames");
                    snapshot
                        .restore(&mut self.world)
                        .expect("the game does not spawn or despawn bodies");
                    self.loaded += 1;
                }
                GgrsRequest::AdvanceFrame { inputs } => {
                    let bits: Vec<u8> = inputs
                        .iter()
                        .map(|&(input, status)| match status {
                            InputStatus::Disconnected => 0,
                            _ => input,
                        })
                        .collect();
                    self.advance(&bits);
                }
            }
        }
    }

    /// How many times the plan had to be rebuilt (a rollback should not cause any).
    pub(super) fn replans(&self) -> u64 {
        self.runner.replans()
    }
}

/// Runs `frames` frames of the game in GGRS's `SyncTestSession`, which rolls back
/// `check_distance` frames every frame, resimulates them and fails on any checksum that differs
/// from the first time that frame was simulated. Returns the game at the end.
pub(super) fn sync_test(
    integrator: Integrator,
    frames: i32,
    check_distance: usize,
) -> Result<Game, GgrsError> {
    let mut session = SessionBuilder::<GameConfig>::new()
        .with_num_players(2)?
        .with_check_distance(check_distance)
        .with_max_prediction_window(check_distance.max(8))
        .add_player(PlayerType::Local, 0)?
        .add_player(PlayerType::Local, 1)?
        .start_synctest_session()?;
    let mut game = Game::new(integrator);
    for frame in 0..frames {
        for player in 0..2 {
            session.add_local_input(player, buttons(player, frame))?;
        }
        let requests = session.advance_frame()?;
        game.handle(requests);
    }
    Ok(game)
}

/// The same inputs without GGRS: every frame simulated once.
pub(super) fn straight(integrator: Integrator, frames: i32) -> Game {
    let mut game = Game::new(integrator);
    for frame in 0..frames {
        game.advance(&[buttons(0, frame), buttons(1, frame)]);
    }
    game
}
