//! What the end of an audited step measured, kept for the start of the next one.
//!
//! The start of a step measures `T + V` of the state the previous step ended with, unless game
//! code changed something in between. So the end pass keeps each body's kinetic energy and each
//! spring's elastic energy, with the number of the pass that measured them, and the next start
//! reuses a body's value where none of its inputs — its [`Pose`], [`Velocity`] and
//! [`MassProps`] — was written since that pass: a memo of a pure function, so a reused value is
//! the value a fresh evaluation would give.
//!
//! "Written since" is read from the components' change ticks ([`Marks`]): three numbers per
//! body, where comparing every input bit for bit read 21 numbers from the world and 14 from the
//! ledger at every start (a quarter of the audit's cost in a loaded spring world). A body's
//! energy is reused where nothing wrote it since the end pass measured it; a spring's link
//! (its ends, stiffness and rest length, which the start pass resolves) and a body's mass (the
//! springs' stiffness bound) are kept where nothing wrote them since the last start pass, so
//! that a force system that rewrites a spring or a mass during a step is seen. Everything
//! that writes a component through `bevy_ecs` marks it (game code's queries and `get_mut`,
//! inserts, a quarantine putting a body back, a rollback restore); a write made with
//! `bypass_change_detection` is not seen, and the next balance then charges what it changed to
//! the integrator. The spring classification trusts the same ticks
//! ([`crate::springs`]).

use bevy_ecs::change_detection::{MAX_CHANGE_AGE, Tick};
use bevy_ecs::system::SystemChangeTick;

/// A body's kinetic energy as an end pass measured it (the ledger entry's entity, at the
/// ledger's end pose).
#[derive(Debug, Clone, Copy)]
pub(super) struct BodyMemo {
    /// The end pass that measured it (0: none).
    pass: u64,
    kinetic: f64,
}

impl BodyMemo {
    /// No measurement.
    pub(super) const NONE: Self = Self {
        pass: 0,
        kinetic: 0.0,
    };

    /// A kinetic energy measured by end pass `pass` (≥ 1).
    pub(super) fn new(pass: u64, kinetic: f64) -> Self {
        Self { pass, kinetic }
    }

    /// True when end pass `pass` (≥ 1) measured it.
    pub(super) fn measured_by(&self, pass: u64) -> bool {
        self.pass != 0 && self.pass == pass
    }

    /// The kinetic energy.
    pub(super) fn kinetic(&self) -> f64 {
        self.kinetic
    }

    /// True when end pass `pass` measured it and the body's inputs were not `written` since:
    /// its kinetic energy and its springs' anchors are as measured. (The caller checks that the
    /// entity is the one measured.)
    #[inline]
    pub(super) fn still(&self, pass: u64, written: bool) -> bool {
        !written && self.measured_by(pass)
    }
}

/// What the start of a step compares change ticks with: the last end pass's tick (a body's
/// energy) and the last start pass's (a spring's link, a body's mass).
#[derive(Debug, Clone, Copy)]
pub(super) struct Marks {
    /// Since the last end pass.
    pub(super) end: EndTick,
    /// Since the last start pass.
    pub(super) start: EndTick,
}

impl Marks {
    /// The ledger's last end and start ticks, read by the start system whose change ticks are
    /// `ticks`. bevy keeps a system's last run in range as the world's counter wraps
    /// (`check_change_ticks`) but not the ticks the ledger stores: they are trusted only while
    /// the start system ran recently (the end pass ran between its last run and this one), so
    /// that physics paused for 2³² ticks of other systems measures everything afresh.
    pub(super) fn new(end: Option<Tick>, start: Option<Tick>, ticks: &SystemChangeTick) -> Self {
        let (now, last) = (ticks.this_run(), ticks.last_run());
        let recent = now.get().wrapping_sub(last.get()) < MAX_CHANGE_AGE / 4;
        let keep = |tick: Option<Tick>| tick.filter(|_| recent);
        Self {
            end: EndTick::new(keep(end), now),
            start: EndTick::new(keep(start), now),
        }
    }
}

/// A tick the ledger stored (an end or start pass's), and the reading system's: whether a
/// component was written since that pass.
#[derive(Debug, Clone, Copy)]
pub(super) struct EndTick {
    /// The end pass's tick; `None` where none ran, or so long ago that ticks no longer order
    /// (every body then counts as written).
    end: Option<Tick>,
    /// The reading system's tick.
    now: Tick,
}

impl EndTick {
    /// The end pass that ran at `end` (if any), read from a system running at `now`.
    pub(super) fn new(end: Option<Tick>, now: Tick) -> Self {
        // Ticks are compared by their age relative to `now`, clamped at `MAX_CHANGE_AGE`:
        // an end pass older than half that is not trusted to order them.
        let end = end.filter(|end| now.get().wrapping_sub(end.get()) < MAX_CHANGE_AGE / 2);
        Self { end, now }
    }

    /// True when a component last changed at `changed` was written at or after the end pass
    /// (the end pass's own deferred commands, a quarantine, count: they carry its tick).
    #[inline(always)]
    pub(super) fn written(&self, changed: Tick) -> bool {
        match self.end {
            Some(end) => !end.is_newer_than(changed, self.now),
            None => true,
        }
    }

    /// [`written`](Self::written) for any of a body's pose, velocity and mass.
    #[inline(always)]
    pub(super) fn any_written(&self, [pose, velocity, mass]: [Tick; 3]) -> bool {
        self.written(pose) | self.written(velocity) | self.written(mass)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A change before the end pass is older; one at its tick (its own deferred commands) or
    /// after is written; without an end pass, or with one too old to order, everything is.
    #[test]
    fn writes_at_or_after_the_end_pass_count() {
        let (end, now) = (Tick::new(1_000), Tick::new(1_010));
        let since = EndTick::new(Some(end), now);
        assert!(!since.written(Tick::new(999)));
        assert!(!since.written(Tick::new(3)));
        assert!(since.written(end));
        assert!(since.written(Tick::new(1_005)));
        assert!(since.any_written([Tick::new(3), Tick::new(1_001), Tick::new(3)]));
        assert!(!since.any_written([Tick::new(3); 3]));
        assert!(EndTick::new(None, now).written(Tick::new(3)));
        // Across the wrap of the counter.
        let wrapped = EndTick::new(Some(Tick::new(u32::MAX - 5)), Tick::new(10));
        assert!(!wrapped.written(Tick::new(u32::MAX - 9)));
        assert!(wrapped.written(Tick::new(2)));
        let ancient = EndTick::new(Some(Tick::new(0)), Tick::new(MAX_CHANGE_AGE));
        assert!(ancient.written(Tick::new(0)));
    }

    /// A memo is reused only for the pass that measured it and a body not written since.
    #[test]
    fn a_memo_is_still_only_for_its_pass_and_an_unwritten_body() {
        let memo = BodyMemo::new(7, 2.5);
        assert!(memo.still(7, false));
        assert!(!memo.still(7, true));
        assert!(!memo.still(8, false));
        assert!(!BodyMemo::NONE.still(0, false));
        assert_eq!(memo.kinetic(), 2.5);
    }
}
