//! The plant: machine, inverter, sensors, load and DC link, stepped one sample at a time.

use fado_core::Abc;
use serde::{Deserialize, Serialize};

use crate::dc_link::{DcLink, DcLinkParams};
use crate::error::SimConfigError;
use crate::faults::{FaultParams, Faults};
use crate::inverter::{Inverter, InverterParams, SampleOutcome};
use crate::load::{Load, LoadParams};
use crate::motor::{Motor, MotorParams};
use crate::sensors::{CurrentSensor, CurrentSensorParams, DcLinkSensorParams, Encoder};

use super::RPM_PER_RAD_S;

/// Everything physical: machine, inverter, sensors, load.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlantParams {
    /// The PMSM.
    pub motor: MotorParams,
    /// Inverter and DC link.
    pub inverter: InverterParams,
    /// Phase-current sensors.
    pub current_sensor: CurrentSensorParams,
    /// DC-link voltage sensor.
    pub dc_link_sensor: DcLinkSensorParams,
    /// Load machine.
    pub load: LoadParams,
    /// Injected faults (none by default).
    pub faults: FaultParams,
    /// The DC link behind the inverter (stiff by default).
    #[serde(default)]
    pub dc_link: DcLinkParams,
    /// The machine's saturating magnetics (`[motor.saturation]` or `[motor] flux_map`); None:
    /// the constant inductances of `motor`. Not a TOML table of its own (the configuration
    /// keeps it under `[motor]`).
    #[serde(skip)]
    pub magnetics: Option<std::sync::Arc<crate::magnetics::PlantMagnetics>>,
}

impl Default for PlantParams {
    /// The paper's plant: its motor ([`MotorParams::paper`]), docs/method/estimator.md §7–6's inverter and
    /// sensors, no load, no faults.
    fn default() -> Self {
        Self {
            motor: MotorParams::paper(),
            inverter: InverterParams::default(),
            current_sensor: CurrentSensorParams::default(),
            dc_link_sensor: DcLinkSensorParams::default(),
            load: LoadParams::default(),
            faults: FaultParams::default(),
            dc_link: DcLinkParams::default(),
            magnetics: None,
        }
    }
}

impl PlantParams {
    /// Checks every record; the error names the key as `section.field`.
    pub fn validate(&self) -> Result<(), SimConfigError> {
        crate::motor::validate_motor_section(&self.motor, self.inverter.dc_voltage)?;
        self.inverter
            .validate()
            .map_err(|e| e.in_section("inverter"))?;
        self.current_sensor
            .validate()
            .map_err(|e| e.in_section("current_sensor"))?;
        self.dc_link_sensor
            .validate()
            .map_err(|e| e.in_section("dc_link_sensor"))?;
        self.load.validate().map_err(|e| e.in_section("load"))?;
        self.faults.validate().map_err(|e| e.in_section("faults"))?;
        self.dc_link
            .validate()
            .map_err(|e| e.in_section("dc_link"))?;
        Ok(())
    }
}

/// The plant: machine, inverter, sensors and load machine.
#[derive(Clone, Debug)]
pub struct Plant {
    motor: Motor,
    inverter: Inverter,
    current_sensor: CurrentSensor,
    dc_link_sensor: DcLinkSensorParams,
    load: Load,
    encoder: Encoder,
    load_torque: f64,
    last: SampleOutcome,
    faults: Option<Faults>,
    dc_link: DcLink,
    /// A holding brake on the shaft: while engaged the rotor stays where it is and the load
    /// acts on the brake.
    brake: bool,
}

impl Plant {
    /// A plant at rest at electrical angle `theta0`.
    pub fn new(params: &PlantParams, theta0: f64) -> Result<Self, SimConfigError> {
        params.validate()?;
        let s = |e: SimConfigError, sec: &str| e.in_section(sec);
        let mo = &params.motor;
        let rated_power = mo.rated_torque * mo.rated_speed_rpm / RPM_PER_RAD_S;
        let dc_link = DcLink::new(&params.dc_link, params.inverter.dc_voltage, rated_power)
            .map_err(|e| s(e, "dc_link"))?;
        let mut plant = Self {
            dc_link,
            motor: Motor::with_magnetics(params.motor, params.magnetics.clone(), theta0)
                .map_err(|e| s(e, "motor"))?,
            inverter: Inverter::new(params.inverter.clone()).map_err(|e| s(e, "inverter"))?,
            current_sensor: CurrentSensor::new(
                params.current_sensor.clone(),
                params.motor.rated_current,
            )
            .map_err(|e| s(e, "current_sensor"))?,
            dc_link_sensor: params.dc_link_sensor.clone(),
            load: Load::new(
                params.load.clone(),
                params.motor.inertia,
                params.motor.rated_speed_rpm,
            )
            .map_err(|e| s(e, "load"))?,
            encoder: Encoder::default(),
            load_torque: 0.0,
            brake: false,
            last: SampleOutcome::default(),
            faults: if params.faults.is_empty() {
                None
            } else {
                Some(
                    Faults::new(params.faults.clone(), params.inverter.sample_period())
                        .map_err(|e| s(e, "faults"))?,
                )
            },
        };
        if let Some(f) = &plant.faults {
            plant.inverter.set_voltage_offset(f.voltage_offset());
        }
        Ok(plant)
    }

    /// The machine (true state).
    pub fn motor(&self) -> &Motor {
        &self.motor
    }

    /// The machine, mutable (initial conditions).
    pub fn motor_mut(&mut self) -> &mut Motor {
        &mut self.motor
    }

    /// The inverter.
    pub fn inverter(&self) -> &Inverter {
        &self.inverter
    }

    /// Sampling period Ts.
    pub fn sample_period(&self) -> f64 {
        self.inverter.sample_period()
    }

    /// Time of the present sample.
    pub fn time(&self) -> f64 {
        self.inverter.time()
    }

    /// Load torque applied over the last sample (N·m, positive opposing positive rotation).
    pub fn load_torque(&self) -> f64 {
        self.load_torque
    }

    /// What the last sample did (average torque and voltage).
    pub fn last_outcome(&self) -> &SampleOutcome {
        &self.last
    }

    /// True phase currents.
    pub fn phase_currents(&self) -> Abc<f64> {
        self.motor.i_ab().to_abc()
    }

    /// Samples the sensors now: (currents, DC-link voltage, encoder mechanical angle), with
    /// the configured faults applied (a DC-link dip acts on the inverter from this sample on).
    pub fn measure(&mut self) -> (Abc<f64>, f64, f64) {
        if let Some(f) = self.faults.as_mut() {
            let k = f.dc_link_scale(self.inverter.time());
            self.inverter.set_dc_link_scale(k);
        }
        let i = self.current_sensor.measure(self.phase_currents());
        let vdc = self.dc_link_sensor.measure(self.inverter.dc_voltage());
        let enc = self.encoder.angle_mech(self.motor.state().theta_mech);
        match &self.faults {
            Some(f) => {
                let (i, vdc) = f.corrupt(self.inverter.time(), i, vdc);
                (i, vdc, enc)
            }
            None => (i, vdc, enc),
        }
    }

    /// Engages the holding brake (the rotor must be at rest: it is held where it is).
    pub fn engage_brake(&mut self) {
        self.brake = true;
    }

    /// Releases the holding brake.
    pub fn release_brake(&mut self) {
        self.brake = false;
    }

    /// Whether the holding brake holds the rotor.
    pub fn brake_engaged(&self) -> bool {
        self.brake
    }

    /// Integrates one sample [n, n+1] and loads `duty_next` for [n+1, n+2].
    pub fn step(&mut self, duty_next: Abc<f64>, gates_enabled: bool) -> SampleOutcome {
        let ts = self.sample_period();
        let t = self.time();
        self.load_torque = self.load.torque(t, self.motor.state().omega_mech, ts);
        let i_before = self.motor.i_ab();
        let out = self
            .inverter
            .step(&mut self.motor, duty_next, gates_enabled);
        if !self.dc_link.is_stiff() {
            // The inverter's power over the sample: 1.5·v·i with the mean current.
            let i_mean = (i_before + self.motor.i_ab()) * 0.5;
            let power = 1.5 * (out.v_ab_avg.alpha * i_mean.alpha + out.v_ab_avg.beta * i_mean.beta);
            let v = self.dc_link.step(self.inverter.source_voltage(), power, ts);
            self.inverter.set_bus_voltage(v);
        }
        if self.brake {
            // The brake takes both torques: the rotor (at rest) does not move.
            self.motor.advance_mechanical(ts, 0.0, 0.0);
        } else {
            self.motor
                .advance_mechanical(ts, out.torque_avg, self.load_torque);
        }
        self.last = out;
        out
    }
}
