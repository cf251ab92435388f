//! `tumble run --plan`: what a run would do, without running it.

use bevy_ecs::prelude::*;
use tumble_core::math::to_f64;
use tumble_ecs::prelude::*;
use tumble_scene::BuiltScene;

use crate::exit::Failure;
use crate::summary::Names;

/// `run --plan`: the systems of the plan, the stages of a step of several, and which method
/// steps which bodies.
pub(crate) fn print_plan(built: &mut BuiltScene) -> Result<(), Failure> {
    let mut out = format!("{}\n", PhysicsPlan::for_world(&mut built.world));
    if let Some(line) = stages_line(&built.world) {
        out.push_str(&format!("{line}\n"));
    }
    let names = Names::new(&mut built.world, &built.bodies);
    out.push_str(&methods_line(&mut built.world, &names));
    crate::stdout::print(&out)
}

/// The stages of a step of several (substeps, a composition), as `--plan` prints them: each
/// stage's span as a multiple of `Δt`, and which substep it belongs to.
fn stages_line(world: &World) -> Option<String> {
    let settings = world.get_resource::<PhysicsSettings>()?;
    let stages = settings.stages();
    if stages.count() == 1 {
        return None;
    }
    let dt = settings.dt();
    let spans: Vec<String> = stages
        .spans(dt)
        .map(|s| format!("{:.6}", to_f64(s.h) / to_f64(dt)))
        .collect();
    Some(format!(
        "stages per step: {} ({} substep(s) × {} of `{}`), h/Δt = {}",
        stages.count(),
        settings.substeps(),
        settings.integrator.composition().len(),
        settings.integrator,
        spans.join(", ")
    ))
}

/// Which method steps which bodies, as `--plan` prints it: the integrator, and the bodies the
/// planner gives another step now (the exact free flow of a split method under
/// `free_flow = auto`, the implicit spring solve for stiff spring groups), with the first of
/// each by name.
fn methods_line(world: &mut World, names: &Names) -> String {
    let Some(settings) = world.get_resource::<PhysicsSettings>().copied() else {
        return String::new();
    };
    let mut out = format!(
        "method: `{}` (free flow `{}`)",
        settings.integrator, settings.free_flow
    );
    for warning in tumble_ecs::stability::check_stability(world) {
        match warning {
            StabilityWarning::ExactFreeFlow { body, bodies, .. } => out.push_str(&format!(
                "; {bodies} {} the exact free flow (`{}`) now, first {}",
                if bodies == 1 {
                    "body takes"
                } else {
                    "bodies take"
                },
                settings
                    .integrator
                    .exact_counterpart()
                    .map_or("exact", |m| m.name()),
                names.of(body)
            )),
            StabilityWarning::ImplicitGroups {
                body,
                bodies,
                midpoint,
                ..
            } => out.push_str(&format!(
                "; {bodies} {} in stiff spring groups, stepped by the implicit spring solve \
                 (rotation by `{}` for {}, by the implicit midpoint for {midpoint}), first {}",
                if bodies == 1 { "body" } else { "bodies" },
                settings.integrator,
                bodies - midpoint,
                names.of(body)
            )),
            StabilityWarning::CannotCombine { body, bodies, .. } => out.push_str(&format!(
                "; {bodies} {} in stiff spring groups, which `{}` cannot step (refused), \
                 first {}",
                if bodies == 1 { "body" } else { "bodies" },
                settings.integrator,
                names.of(body)
            )),
            _ => {}
        }
    }
    out.push('\n');
    out
}
