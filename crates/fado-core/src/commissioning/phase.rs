//! The procedure's phases, the parameters it identifies, why it aborts and where it stands.

/// The phases of the procedure, in order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    /// Gates off, sensor offsets measured.
    Offset,
    /// Rotor aligned with the α axis (rotation expected).
    Align,
    /// Two-level DC test: Rs and the inverter voltage error.
    Resistance,
    /// Square-wave injection along d.
    InductanceD,
    /// Square-wave injection along q.
    InductanceQ,
    /// Bipolar flux-linkage pulses up to the rated current: the magnetic model.
    Magnetics,
    /// I-f open-loop acceleration.
    Spin,
    /// No q current (the d current at −½ the limit), rotor coasting: the first back-EMF
    /// window.
    Coast,
    /// Torque steps in closed loop, with the second back-EMF window between them: λf, J and
    /// friction.
    Inertia,
    /// Finished; the result is available.
    Done,
    /// Aborted; see [`Commissioning::status`](crate::commissioning::Commissioning::status).
    Aborted,
}

impl Phase {
    /// Short name (for traces and progress bars).
    pub fn name(self) -> &'static str {
        match self {
            Phase::Offset => "offset",
            Phase::Align => "align",
            Phase::Resistance => "resistance",
            Phase::InductanceD => "inductance_d",
            Phase::InductanceQ => "inductance_q",
            Phase::Magnetics => "magnetics",
            Phase::Spin => "spin",
            Phase::Coast => "coast",
            Phase::Inertia => "inertia",
            Phase::Done => "done",
            Phase::Aborted => "aborted",
        }
    }

    /// Index 0–10 in procedure order.
    pub fn index(self) -> usize {
        self as usize
    }
}

/// A parameter of the result (for [`AbortReason::Implausible`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Parameter {
    /// Stator resistance.
    Rs,
    /// Inverter voltage error.
    InverterVoltage,
    /// d-axis inductance.
    Ld,
    /// q-axis inductance.
    Lq,
    /// Magnet flux linkage.
    FluxLinkage,
    /// Inertia.
    Inertia,
    /// Viscous friction.
    ViscousFriction,
}

/// Why the procedure stopped early. The gates are off from the sample it is reported on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AbortReason {
    /// The rotor turned during a standstill phase (alternating current error with the voltage
    /// unsaturated: a back-EMF the regulator cannot follow), e.g. a load that drives it.
    RotationDetected {
        /// Where.
        phase: Phase,
    },
    /// The current did not reach its reference with the voltage at its limit (an open phase,
    /// a missing motor, a far too high resistance), went beyond the trip mostly across its
    /// reference at standstill (an open phase), or lost its reference in a spin.
    CurrentNotFollowing {
        /// Where.
        phase: Phase,
    },
    /// A measured current beyond `trip_ratio` × the current limit.
    OverCurrent {
        /// Where.
        phase: Phase,
    },
    /// The estimated speed beyond twice the highest test speed, or the rotor stalled / lost
    /// in a spin.
    Overspeed {
        /// Where.
        phase: Phase,
    },
    /// A phase ran past its maximum duration.
    Timeout {
        /// Where.
        phase: Phase,
    },
    /// A result is non-finite, non-positive or outside 1/4–4× the nameplate (J: 1/10–10×).
    Implausible {
        /// Which parameter.
        parameter: Parameter,
    },
    /// More than 10 ms of consecutive non-finite current or DC-link samples.
    NonFiniteMeasurements {
        /// Where.
        phase: Phase,
    },
    /// The rotor's speed moves too fast for a measurement: in the inertia test
    /// ([`Phase::Inertia`]) the torque steps, at the smallest step the current resolution
    /// allows, ended too soon for the regression's windows; in the coast ([`Phase::Coast`])
    /// its friction slowed it below a quarter of the spin speed before the back-EMF window
    /// ended. The rotor is too light to be measured (with these current sensors, or against
    /// its friction).
    RotorTooLight {
        /// Where.
        phase: Phase,
        /// The speed the rotor gained in the step up, or lost in the coast, r/min
        /// (mechanical).
        speed_rpm: u32,
        /// The time it took, ms.
        time_ms: u32,
        /// The time the measurement needs, ms.
        needed_ms: u32,
    },
}

impl core::fmt::Display for AbortReason {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            AbortReason::RotorTooLight {
                phase: Phase::Coast,
                speed_rpm,
                time_ms,
                needed_ms,
            } => write!(
                f,
                "the rotor loses {speed_rpm} r/min in {time_ms} ms coasting: too light against \
                 its friction for the back-EMF window, which needs {needed_ms} ms (a load \
                 coupled to the rotor)"
            ),
            AbortReason::RotorTooLight {
                speed_rpm,
                time_ms,
                needed_ms,
                ..
            } => write!(
                f,
                "the rotor reaches {speed_rpm} r/min in {time_ms} ms under the smallest torque \
                 step: too light for the inertia test, which needs {needed_ms} ms (a finer \
                 current sensor, or a load coupled to the rotor)"
            ),
            AbortReason::Implausible { parameter } => {
                write!(f, "implausible result: {parameter:?}")
            }
            other => write!(f, "{other:?}"),
        }
    }
}

/// Where the procedure stands.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Status {
    /// Still running.
    Running,
    /// Finished: see [`Commissioning::result`](crate::commissioning::Commissioning::result).
    Done,
    /// Stopped early, gates off.
    Aborted(AbortReason),
}
