//! Each bundled scene gets exactly the systems it needs, no more: the expected lists follow from
//! the rules of `PhysicsPlan` (a gravity system only for bodies with accumulators, one system per
//! kind of generator, the first half-drift only for drift–kick–drift methods with forces, the
//! implicit spring step only for spring groups stiff for the step).

use bevy_ecs::prelude::World;
use tumble_ecs::prelude::PhysicsPlan;
use tumble_scene::load_scene;

fn plan_of(name: &str) -> (String, usize) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes")
        .join(format!("{name}.toml"));
    let mut built = load_scene(&path).unwrap().build();
    let world: &mut World = &mut built.world;
    assert_eq!(&PhysicsPlan::for_world(world), built.physics.plan());
    let plan = built.physics.plan();
    (plan.to_string(), plan.systems().len())
}

#[test]
fn every_bundled_scene_has_exactly_the_systems_it_needs() {
    let free = "integrate_without_forces";
    let expected = [
        // Torque-free bodies (gravity, where present, is applied inside the integrate pass).
        ("dzhanibekov", free),
        ("far_away", free),
        ("long_run", free),
        ("principal_spins", free),
        ("projectile", free),
        ("thin_rod", free),
        ("thin_plate", free),
        // A force at a point on the top; springs between bodies (with the energy audit that
        // every spring network gets).
        (
            "spinning_top",
            "begin_stage → apply_constant_forces → integrate_with_forces",
        ),
        // The chain is stiff for its step (√(2k/m)Δt = 1.05, above the implicit threshold
        // 0.3): the implicit spring step takes the whole group, and nothing is left for the
        // explicit systems; one spring has a damper, whose flow is split around the step.
        (
            "spring_chain",
            "audit_energy_start → damp_springs_start → audit_external_loads → \
             solve_implicit_springs → damp_springs_end → audit_energy",
        ),
        // √(k/m)Δt = 1.0 for the light body: implicit as well.
        (
            "mass_ratio",
            "audit_energy_start → audit_external_loads → solve_implicit_springs → audit_energy",
        ),
    ];
    let expected = expected.into_iter().chain([
        // Stiff on purpose (√(k/μ)Δt = 10): implicit, and gravity for the cloth.
        (
            "stiff_chain",
            "audit_energy_start → audit_external_loads → solve_implicit_springs → audit_energy",
        ),
        (
            "cloth",
            "audit_energy_start → apply_gravity → audit_external_loads → solve_implicit_springs → \
             audit_energy",
        ),
    ]);
    for (scene, systems) in expected {
        let (plan, count) = plan_of(scene);
        assert_eq!(plan, systems, "{scene}");
        assert_eq!(
            count,
            systems.split(" → ").count(),
            "{scene}: schedule size"
        );
    }
}
