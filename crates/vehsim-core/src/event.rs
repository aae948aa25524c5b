//! What happens during a run and how it ends: the engine's vocabulary, shared by every layer that
//! reports something (a tyre leaving its measured range, a vehicle state going non-finite, a cone
//! strike) without depending on the engine itself.

/// Something that happened during a run, with its time.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Event {
    /// Time, s.
    pub t_s: f64,
    /// What happened (serialised in snake case: `cone_strike`, `spin_out`, ...).
    pub kind: EventKind,
    /// Human-readable detail (which gate and side, which state went non-finite, ...).
    pub detail: String,
}

/// The kinds of [`Event`], serialised (summary.json) as their snake-case names ([`EventKind::as_str`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum EventKind {
    /// ISO 3888-2: the car left the course's exit (the manoeuvre's end).
    CourseComplete,
    /// ISO 3888-2: a gate boundary (cone line) was struck.
    ConeStrike,
    /// Constant radius: one more lap of the circle.
    LapComplete,
    /// Constant radius: the car left the circle beyond the path tolerance.
    LeftPath,
    /// The state became non-finite or the adaptive solver gave up.
    Diverged,
    /// |sideslip| exceeded the spin-out limit.
    SpinOut,
    /// A watched condition flapped too often; its further events are not reported.
    EventsSuppressed,
    /// 4-DOF model: a wheel's normal load reached zero, and its return.
    WheelLift,
    /// 4-DOF model: a lifted wheel's normal load became positive again.
    WheelContact,
    /// 4-DOF model: a normal load went negative before clamping, and its return.
    NegativeNormalLoad,
    /// 4-DOF model: a normal load that went negative before clamping is positive again.
    NormalLoadRestored,
    /// Plausibility: a tyre force beyond the friction limit, and its return.
    TyreForceBeyondFriction,
    /// Plausibility: the tyre force is back within the friction limit.
    TyreForceWithinFriction,
    /// Plausibility: lateral acceleration beyond mu g, and its return.
    AyBeyondFriction,
    /// Plausibility: lateral acceleration is back within mu g.
    AyWithinFriction,
    /// Plausibility: the car beyond the path tolerance, and its return.
    PathExit,
    /// Plausibility: the car is back within the path tolerance.
    PathReturn,
    /// The contact-temperature model could not be built; the run went on isothermal.
    ContactModelUnavailable,
    /// Thermal Dugoff: the published temperature factor would reverse F_x; it was clamped.
    ThermalFactorClamped,
    /// Plausibility by the tyre's range: an axle's slip ratio left the tyre file's declared
    /// range, and its return; likewise the slip angle and a wheel's normal load.
    SlipRatioBeyondRange,
    /// Plausibility: the axle's slip ratio is back within the tyre file's declared range.
    SlipRatioWithinRange,
    /// Plausibility: an axle's slip angle left the tyre file's declared range.
    SlipAngleBeyondRange,
    /// Plausibility: the axle's slip angle is back within the tyre file's declared range.
    SlipAngleWithinRange,
    /// Plausibility: a wheel's normal load left the tyre file's declared load range.
    LoadBeyondRange,
    /// Plausibility: the wheel's normal load is back within the tyre file's declared load range.
    LoadWithinRange,
}

impl EventKind {
    /// The serialised name.
    pub fn as_str(self) -> &'static str {
        match self {
            EventKind::CourseComplete => "course_complete",
            EventKind::ConeStrike => "cone_strike",
            EventKind::LapComplete => "lap_complete",
            EventKind::LeftPath => "left_path",
            EventKind::Diverged => "diverged",
            EventKind::SpinOut => "spin_out",
            EventKind::EventsSuppressed => "events_suppressed",
            EventKind::WheelLift => "wheel_lift",
            EventKind::WheelContact => "wheel_contact",
            EventKind::NegativeNormalLoad => "negative_normal_load",
            EventKind::NormalLoadRestored => "normal_load_restored",
            EventKind::TyreForceBeyondFriction => "tyre_force_beyond_friction",
            EventKind::TyreForceWithinFriction => "tyre_force_within_friction",
            EventKind::AyBeyondFriction => "ay_beyond_friction",
            EventKind::AyWithinFriction => "ay_within_friction",
            EventKind::PathExit => "path_exit",
            EventKind::PathReturn => "path_return",
            EventKind::ContactModelUnavailable => "contact_model_unavailable",
            EventKind::ThermalFactorClamped => "thermal_factor_clamped",
            EventKind::SlipRatioBeyondRange => "slip_ratio_beyond_range",
            EventKind::SlipRatioWithinRange => "slip_ratio_within_range",
            EventKind::SlipAngleBeyondRange => "slip_angle_beyond_range",
            EventKind::SlipAngleWithinRange => "slip_angle_within_range",
            EventKind::LoadBeyondRange => "load_beyond_range",
            EventKind::LoadWithinRange => "load_within_range",
        }
    }

    /// The onsets of the friction checks: a result beyond what the surface can carry.
    pub fn beyond_friction(self) -> bool {
        matches!(self, EventKind::TyreForceBeyondFriction | EventKind::AyBeyondFriction)
    }
}

named_by_as_str!(EventKind);

/// Why a run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum EndReason {
    /// The manoeuvre finished (its own end rule).
    Completed,
    /// The time limit `duration_s` was reached.
    Duration,
    /// |sideslip| exceeded 60 degrees above 1 m/s.
    SpinOut,
    /// The state became non-finite or the adaptive solver gave up.
    Diverged,
    /// The car left the path beyond the manoeuvre's tolerance (constant radius: off the circle).
    /// Not a failure of the run: on a circle stepped to the friction limit it is how the run
    /// reaches its end; the summary's plausibility reasons say so.
    LeftPath,
}

impl EndReason {
    /// Every end reason, in declaration order.
    pub const ALL: [EndReason; 5] =
        [EndReason::Completed, EndReason::Duration, EndReason::SpinOut, EndReason::Diverged, EndReason::LeftPath];

    /// The serialised name.
    pub fn as_str(self) -> &'static str {
        match self {
            EndReason::Completed => "completed",
            EndReason::Duration => "duration",
            EndReason::SpinOut => "spin_out",
            EndReason::Diverged => "diverged",
            EndReason::LeftPath => "left_path",
        }
    }

    /// Divergence and spin-out are failures of the run.
    pub fn failed(self) -> bool {
        matches!(self, EndReason::SpinOut | EndReason::Diverged)
    }
}

named_by_as_str!(EndReason);
