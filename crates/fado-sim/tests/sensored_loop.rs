//! The plant in closed loop with a textbook sensored FOC (encoder angle, PI current control
//! with decoupling, PI speed control, min-max SVPWM, delay compensation): checks that the
//! plant, the inverter models and the runner behave like a drive should, independently of the
//! sensorless drive.

use fado_core::{Abc, Dq, Estimate, Rotation};
use fado_sim::controller::{Actuation, Controller, Measurements};
use fado_sim::inverter::InverterModel;
use fado_sim::profile::Profile;
use fado_sim::sim::{Metrics, Plant, PlantParams, Probe, Sample, Simulation};

struct SensoredFoc {
    pp: f64,
    ts: f64,
    kp_i: f64,
    ki_i: f64,
    kp_w: f64,
    ki_w: f64,
    int_i: Dq<f64>,
    int_w: f64,
    l: f64,
    lf: f64,
    theta_prev: Option<f64>,
    omega: f64,
    comp_v: f64,
}

impl SensoredFoc {
    fn new(comp_v: f64) -> Self {
        let (l, r, j, kt) = (2.63e-3, 0.327, 0.012, 1.5 * 4.0 * 0.088);
        let wc = std::f64::consts::TAU * 250.0;
        let ws = std::f64::consts::TAU * 5.0;
        let kp_w = j * ws / kt;
        Self {
            pp: 4.0,
            ts: 1e-4,
            kp_i: l * wc,
            ki_i: r * wc,
            kp_w,
            ki_w: kp_w * ws / 5.0,
            int_i: Dq::zero(),
            int_w: 0.0,
            l,
            lf: 0.088,
            theta_prev: None,
            omega: 0.0,
            comp_v,
        }
    }
}

impl Controller for SensoredFoc {
    fn align(&mut self, _theta0: f64) {}

    fn step(&mut self, m: &Measurements) -> Actuation {
        let theta = m.encoder_angle_mech * self.pp;
        if let Some(prev) = self.theta_prev {
            let w = fado_core::wrap_angle(theta - prev) / self.ts;
            self.omega += 0.05 * (w - self.omega); // ~80 Hz low-pass of the encoder speed
        }
        self.theta_prev = Some(theta);
        let i_ab = m.i_abc.to_ab();
        let i = i_ab.to_dq(Rotation::from_angle(theta));
        let e_w = m.speed_ref_mech * self.pp - self.omega;
        self.int_w += self.ki_w * self.ts * e_w / self.pp;
        let iq_ref = (self.kp_w * e_w / self.pp + self.int_w).clamp(-40.0, 40.0);
        let i_ref = Dq::new(0.0, iq_ref);
        let e = i_ref - i;
        self.int_i += e * (self.ki_i * self.ts);
        let w = self.omega;
        let v = Dq::new(
            self.kp_i * e.d + self.int_i.d - w * self.l * i.q,
            self.kp_i * e.q + self.int_i.q + w * (self.l * i.d + self.lf),
        );
        let v_ab = v.to_ab(Rotation::from_angle(theta + 1.5 * w * self.ts));
        // Sign-based dead-time compensation of the reference current's phases.
        let i_ref_abc = i_ref
            .to_ab(Rotation::from_angle(theta + 1.5 * w * self.ts))
            .to_abc();
        let sgn = |x: f64| (x / 0.3).clamp(-1.0, 1.0);
        let comp = Abc::new(sgn(i_ref_abc.a), sgn(i_ref_abc.b), sgn(i_ref_abc.c)) * self.comp_v;
        let v_abc = (v_ab.to_abc() + comp) * (1.0 / m.vdc);
        let mid = 0.5 * (v_abc.a.max(v_abc.b).max(v_abc.c) + v_abc.a.min(v_abc.b).min(v_abc.c));
        let duty = Abc::new(
            (0.5 + v_abc.a - mid).clamp(0.0, 1.0),
            (0.5 + v_abc.b - mid).clamp(0.0, 1.0),
            (0.5 + v_abc.c - mid).clamp(0.0, 1.0),
        );
        Actuation {
            duty,
            gates_enabled: true,
            v_ref_ab: v_ab,
            i_dq: i,
            i_dq_ref: i_ref,
            estimate: Estimate {
                theta,
                omega: w,
                omega_control: w,
                ..Default::default()
            },
            ..Default::default()
        }
    }

    fn name(&self) -> &str {
        "sensored"
    }
}

struct CurrentError {
    worst_late: f64,
    t_from: f64,
}

impl Probe for CurrentError {
    fn observe(&mut self, s: &Sample) {
        if s.time > self.t_from {
            let e = s.act.i_dq_ref.q - s.i_dq_true.q;
            self.worst_late = self.worst_late.max(e.abs());
        }
    }
}

fn run(model: InverterModel, comp_v: f64) -> (Metrics, f64, f64) {
    let mut params = PlantParams::default();
    params.inverter.model = model;
    params.load.torque = Profile::from_points(&[(0.0, 0.0), (0.5, 0.0), (0.6, 7.5)]);
    let plant = Plant::new(&params, 0.3).unwrap();
    let speed = Profile::from_points(&[(0.0, 0.0), (0.3, 300.0)]);
    let mut sim = Simulation::new(plant, SensoredFoc::new(comp_v), speed, 0.0).unwrap();
    let mut metrics = Metrics::new(1.2, 30.0);
    let mut cur = CurrentError {
        worst_late: 0.0,
        t_from: 1.2,
    };
    sim.run(1.5, &mut [&mut metrics, &mut cur], None);
    let st = sim.plant().motor().state();
    (
        metrics,
        st.omega_mech * 60.0 / std::f64::consts::TAU,
        cur.worst_late,
    )
}

#[test]
fn sensored_foc_tracks_speed_under_load_in_both_inverter_models() {
    for model in [InverterModel::SwitchingResolved, InverterModel::Averaged] {
        let (m, rpm, cur_err) = run(model, 3.9);
        assert!(!m.tripped);
        assert!((rpm - 300.0).abs() < 2.0, "{model:?}: {rpm} r/min");
        assert!(
            m.max_speed_error_rpm < 5.0,
            "{model:?}: {}",
            m.max_speed_error_rpm
        );
        // q current settles on 7.5 N·m / Kt ≈ 14.2 A with the PI (ripple of the resolved
        // model filtered by synchronous sampling).
        assert!(cur_err < 1.0, "{model:?}: |iq* − iq| = {cur_err}");
    }
}

#[test]
fn the_two_inverter_models_agree_on_the_average_behaviour() {
    // Same controller, same sensors: the averaged model reproduces the switching-resolved
    // speed trajectory (its dead-time error curve is the one of the resolved model, smoothed).
    let (a, rpm_a, _) = run(InverterModel::SwitchingResolved, 3.9);
    eprintln!("{a:?} {rpm_a}");
    let (b, rpm_b, _) = run(InverterModel::Averaged, 3.9);
    assert!((rpm_a - rpm_b).abs() < 0.5, "{rpm_a} vs {rpm_b}");
    assert!((a.max_speed_error_rpm - b.max_speed_error_rpm).abs() < 1.0);
}
