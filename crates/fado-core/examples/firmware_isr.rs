//! How firmware uses the estimator: one `step` per 10 kHz PWM interrupt, in `f32`, with the
//! voltage that actually acted over the last interval. The ISR body below is what the README
//! quotes; `main` only plays the part of the hardware (an ideal motor at 200 r/min) so that the
//! example runs on a PC:
//!
//! ```text
//! cargo run --release -p fado-core --example firmware_isr
//! ```

use fado_core::{Ab, Abc, Dq, EstimatorConfig, MachineModel, Rotation, SensorlessEstimator};

/// The estimator part of a drive's 10 kHz interrupt.
pub struct Isr {
    estimator: SensorlessEstimator<f32>,
    /// Voltage references of the last two samples, newest first. The one computed two samples
    /// ago is the one the PWM applied over the interval that just ended (one sample of
    /// computation delay, docs/method/estimator.md §1).
    v_ref: [Ab<f32>; 2],
    /// Input faults seen (NaN from a broken ADC channel, say).
    pub faults: u32,
}

impl Isr {
    /// Set-up, before the interrupt is enabled: the motor's data (parameters and ratings, here
    /// the paper's motor), the paper's tuning for everything else, and a start at a known
    /// (aligned) rotor angle with the phase currents flowing then (docs/method/estimator.md, "Start-up":
    /// λ1 = λ̂f·e^{jθ0} + L̂q·i).
    pub fn new(theta_aligned: f32, i_abc: Abc<f32>) -> Self {
        let motor = MachineModel {
            rs: 0.327,
            ld: 2.63e-3,
            lq: 2.63e-3,
            flux_linkage: 0.088,
            pole_pairs: 4,
            inertia: 0.012,
            viscous_friction: 1e-3,
            rated_current: 21.78,
            rated_speed_rpm: 1500.0,
            rated_torque: 11.5,
            dc_voltage: 311.0,
            magnetics: Default::default(),
        };
        let config = EstimatorConfig {
            initial_angle: theta_aligned,
            ..EstimatorConfig::for_machine(&motor)
        };
        let mut estimator = SensorlessEstimator::new(config).expect("motor data are valid");
        estimator.align(theta_aligned, i_abc.to_ab());
        Self {
            estimator,
            v_ref: [Ab::zero(); 2],
            faults: 0,
        }
    }

    /// The interrupt: phase currents in (A), the new voltage reference out (V, α-β), with the
    /// angle and speed for the current and speed controllers in between.
    pub fn on_pwm_interrupt(&mut self, i_abc: Abc<f32>) -> (f32, f32) {
        let i_ab = i_abc.to_ab();
        let estimate = self.estimator.step(self.v_ref[1], i_ab);
        if estimate.diagnostics.input_fault {
            // The sample was refused and the state left as it was; the estimate repeats the last
            // good one. A drive would count these and trip after a few in a row.
            self.faults += 1;
        }
        let theta = estimate.theta; // rotor angle for the Park transforms
        let speed = estimate.omega_control; // electrical rad/s for the speed loop
        // ... current control would compute the next voltage reference here ...
        (theta, speed)
    }

    /// Stores the voltage reference the current controller just computed.
    pub fn set_voltage_reference(&mut self, v_ab: Ab<f32>) {
        self.v_ref = [v_ab, self.v_ref[0]];
    }
}

fn main() {
    // The "hardware": an ideal motor at 200 r/min (13.3 Hz electrical) with 6 A on q. Its
    // controller is replaced by the voltage that exactly moves the motor's flux, handed to the
    // ISR two samples ahead as the real reference would be.
    let (ts, rs, l, lf) = (100e-6_f64, 0.327, 2.63e-3, 0.088);
    let omega = 200.0 * 4.0 * core::f64::consts::TAU / 60.0;
    let i_dq = Dq::new(0.0, 6.0);
    let theta = |n: usize| omega * ts * n as f64;
    let machine = |n: usize| {
        let rot = Rotation::from_angle(theta(n));
        (
            Dq::new(lf + l * i_dq.d, l * i_dq.q).to_ab(rot),
            i_dq.to_ab(rot),
        )
    };
    // The voltage over the interval (n − 1, n].
    let interval_voltage = |n: usize| {
        let ((l0, i0), (l1, i1)) = (machine(n - 1), machine(n));
        let v = (l1 - l0) * (1.0 / ts) + (i0 + i1) * (0.5 * rs);
        Ab::new(v.alpha as f32, v.beta as f32)
    };

    let i0 = machine(0).1.to_abc();
    let mut isr = Isr::new(
        theta(0) as f32,
        Abc::new(i0.a as f32, i0.b as f32, i0.c as f32),
    );
    isr.set_voltage_reference(interval_voltage(1));
    isr.set_voltage_reference(interval_voltage(2));
    let mut worst: f64 = 0.0;
    for n in 1..=20_000 {
        let i = machine(n).1.to_abc();
        let (theta_hat, _speed) =
            isr.on_pwm_interrupt(Abc::new(i.a as f32, i.b as f32, i.c as f32));
        isr.set_voltage_reference(interval_voltage(n + 2));
        if n > 10_000 {
            worst = worst.max(fado_core::wrap_angle(theta(n) - f64::from(theta_hat)).abs());
        }
    }
    println!(
        "200 r/min, 6 A: worst |θ − θ̂| over the second second {worst:.2e} rad, {} input faults",
        isr.faults
    );
}
