//! # tumble_report
//!
//! The numbers users read to choose an integrator and a time step:
//!
//! - **work–precision** ([`workprec`]): for each reference scene with an exact solution, each
//!   integrator (and rapier as a row) and Δt from 1/15 to 1/1920 s, the error at a fixed horizon
//!   (orientation angle, position, relative energy and `|L|` drift) and the run time per
//!   body-step, measured in the same process;
//! - **stability matrix** ([`stability`]): extreme scenes × integrator × setting: finite?
//!   `max ||q| − 1|`? final/initial energy? and whether tumble's stability prediction warned;
//! - **the thin asymmetric plate** ([`thin`]) at `|ω|Δt` = 0.1 … 3, every integrator, against
//!   the closed-form top;
//! - **energy over time** ([`energy`]) for long spins, each method and rapier;
//! - **springs against rapier** ([`springs`], [`spring_output`]): the stiff chain
//!   ([`tumble_rapier::presets::spring_chain`]) at several `ωΔt`, tumble's explicit and implicit spring steps against rapier's
//!   `SpringJoint` and a hand-written spring force: energy over time and time per step;
//! - **outputs** ([`output`]): `report.md`, `results.json` and SVG plots.

#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod energy;
pub mod linkage;
pub mod output;
pub mod plots;
pub mod reference;
pub mod run;
pub mod spring_output;
pub mod springs;
pub mod stability;
pub mod storage;
pub mod thin;
pub mod workprec;
