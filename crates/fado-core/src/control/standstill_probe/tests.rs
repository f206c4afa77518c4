use super::*;

/// A synthetic loaded standstill: a rotor (λf, Ld − Lq) at angle error δ = θ − θ̂ under a
/// load `load` (torque in units of 1.5·p, i.e. Wb·A), with the drive's model feed-forward
/// λ̂a(i_d̂)·i_q̂ = λf·τ and a settled speed loop: τ is whatever makes the true torque
/// (λf + ΔL·i_d)·i_q equal the load, i_d = i_d̂·cos δ + i_q̂·sin δ,
/// i_q = i_q̂·cos δ − i_d̂·sin δ.
struct Balance {
    flux: f64,
    saliency: f64,
    delta: f64,
    load: f64,
}

impl Balance {
    fn currents(&self, tau: f64, i_d_hat: f64) -> (f64, f64) {
        let i_q_hat = self.flux * tau / (self.flux + self.saliency * i_d_hat);
        (i_d_hat, i_q_hat)
    }
    fn torque(&self, tau: f64, i_d_hat: f64) -> f64 {
        let (dh, qh) = self.currents(tau, i_d_hat);
        let (s, c) = self.delta.sin_cos();
        let (i_d, i_q) = (dh * c + qh * s, qh * c - dh * s);
        (self.flux + self.saliency * i_d) * i_q
    }
    /// The settled torque demand for a d reference `i_d_hat` (bisection).
    fn tau(&self, i_d_hat: f64) -> f64 {
        let (mut lo, mut hi) = (0.0, 10.0 * self.load / self.flux);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if self.torque(mid, i_d_hat) < self.load {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        0.5 * (lo + hi)
    }
}

fn probe(amplitude: f64) -> StandstillProbe<f64> {
    StandstillProbe::new(StandstillProbeConfig {
        ts: 1e-3,
        amplitude,
        period: 0.2,
        gain: 0.25,
        max_speed: 1.0,
        min_load: 1.0,
        inertia: 0.0,
        swing: 0.0,
        arm_time: 0.2,
    })
    .unwrap()
}

/// Runs the probe against the balance (τ lags the settled value with a first-order
/// time constant `lag` in samples, the speed loop) for the arming period and one probe
/// period; returns the reading.
fn read(b: &Balance, i_d0: f64, amplitude: f64, lag: f64) -> f64 {
    let mut p = probe(amplitude);
    let mut tau = b.tau(i_d0);
    let mut id = i_d0;
    for _ in 0..400 {
        let iq = b.currents(tau, id).1;
        let did = p.step(true, true, tau, 0.0, (id, iq), b.flux, b.saliency);
        id = i_d0 + did;
        tau += (b.tau(id) - tau) / lag;
    }
    assert!(p.active());
    p.reading()
}

#[test]
fn surface_magnet_reading_is_the_angle_error_with_its_sign() {
    // The paper's motor: λf 0.1 Wb, 14 A of load, 2.2 A probe.
    for delta in [-0.4, -0.2, -0.05, 0.0, 0.05, 0.2, 0.4] {
        let b = Balance {
            flux: 0.1,
            saliency: 0.0,
            delta,
            load: 1.4,
        };
        let r = read(&b, 0.0, 2.2, 1.0);
        assert!(
            (r - delta).abs() < 0.01 * delta.abs() + 1e-6,
            "δ {delta}: read {r}"
        );
        // With the speed loop's lag (time constant 10 of the 100-sample half-period):
        let r = read(&b, 0.0, 2.2, 10.0);
        assert!(
            (r - delta).abs() < 0.02 * delta.abs() + 1e-6,
            "δ {delta}: lagged {r}"
        );
    }
    // No response to the probe (δ = 0 held by a stiff τ): no reading, no turn.
    let mut p = probe(2.2);
    let tau = b_tau_zero();
    for _ in 0..400 {
        p.step(true, true, tau, 0.0, (0.0, tau), 0.1, 0.0);
    }
    assert!(p.active() && p.reading() == 0.0 && p.rate() == 0.0);
}

fn b_tau_zero() -> f64 {
    14.0
}

#[test]
fn interior_magnet_reading_accounts_for_the_reluctance_torque() {
    // The 2.2 kW IPMSM: λf 0.545 Wb, Ld − Lq = −15 mH, half load (3.3 A) with
    // i_d = −0.5 A, a 0.6 A probe. The reluctance torque alone would read
    // atan(ΔL·i_q/λa) = −0.09 rad at δ = 0; the reading removes it. The ±A step is a
    // finite difference of the balance, not its derivative: 3.5 % of δ at δ = −0.3.
    for delta in [-0.3, -0.1, 0.0, 0.1, 0.3] {
        let b = Balance {
            flux: 0.545,
            saliency: -0.015,
            delta,
            load: 0.545 * 3.3,
        };
        let r = read(&b, -0.5, 0.6, 1.0);
        assert!(
            (r - delta).abs() < 0.05 * delta.abs() + 1e-4,
            "δ {delta}: read {r}"
        );
        let r = read(&b, -0.5, 0.6, 10.0);
        assert!(
            (r - delta).abs() < 0.06 * delta.abs() + 1e-4,
            "δ {delta}: lagged {r}"
        );
    }
}

#[test]
fn angle_reading_inverts_the_small_signal_balance() {
    // λ̂f·Δτ/Δi_d = b + λa·tan(δ − φ) (module docs), for both rotors.
    for (flux, saliency, i_d, i_q) in [(0.1, 0.0, 0.0, 14.0), (0.545, -0.015, -0.5, 3.3)] {
        let lambda_a: f64 = flux + saliency * i_d;
        let b = saliency * i_q;
        let phi = (b / lambda_a).atan();
        for delta in [-0.4, 0.0, 0.25] {
            let dtau = (b + lambda_a * (delta - phi).tan()) / flux;
            let r = angle_reading(dtau, 1.0, i_d, i_q, flux, saliency);
            assert!((r - delta).abs() < 1e-12, "{r} vs {delta}");
        }
    }
}

#[test]
fn the_gate_stops_the_probe_and_the_turn() {
    let b = Balance {
        flux: 0.1,
        saliency: 0.0,
        delta: 0.3,
        load: 1.4,
    };
    let mut p = probe(2.2);
    let mut id = 0.0;
    let mut tau = b.tau(0.0);
    for _ in 0..400 {
        id = p.step(true, true, tau, 0.0, (id, tau), 0.1, 0.0);
        tau = b.tau(id);
    }
    let first = 0.25 * (1.0 + CREEP_GAIN_RATIO) * p.reading();
    assert!(p.rate() > 0.0 && (p.rate() - first).abs() < 1e-12);
    assert!(p.gate(0.5, 5.0, true) && p.gate(-0.5, -5.0, true));
    assert!(!p.gate(2.0, 5.0, true) && !p.gate(0.0, 0.5, true));
    assert!(!p.gate(0.0, 5.0, false));
    // The standstill ends in limiter mode: the probe stops and its turn is carried, the last
    // reading's proportional part for 1/g (here 4 s: it turns θ̂ by the reading once), the
    // learned creep until limiter mode ends.
    let creep = CREEP_GAIN_RATIO * 0.25 * p.reading();
    assert_eq!(p.step(false, true, tau, 0.0, (0.0, tau), 0.1, 0.0), 0.0);
    assert!(
        !p.active() && (p.rate() - first).abs() < 1e-12,
        "{}",
        p.rate()
    );
    for _ in 0..4000 {
        p.step(false, true, tau, 0.0, (0.0, tau), 0.1, 0.0);
    }
    assert!((p.rate() - creep).abs() < 1e-12, "{} {creep}", p.rate());
    p.step(false, false, tau, 0.0, (0.0, tau), 0.1, 0.0);
    assert_eq!((p.rate(), p.active()), (0.0, false));
    assert_eq!(p.step(true, true, f64::NAN, 0.0, (0.0, tau), 0.1, 0.0), 0.0);
    // Off (amplitude 0): never gated.
    assert!(!probe(0.0).gate(0.0, 5.0, true));
}

/// A rigid rotor under the speed PI (5 Hz, zero at a fifth of it), period 0.1 s: the
/// speed loop has not settled within a half-period, so τ alone under-reads the torque
/// balance; with the rotor's acceleration removed (`inertia`) the reading is the angle.
#[test]
fn inertia_term_reads_an_unsettled_speed_loop() {
    let (flux, c_j, ts) = (0.1, 2e-3, 1e-4);
    let read = |delta: f64, inertia: f64| {
        let b = Balance {
            flux,
            saliency: 0.0,
            delta,
            load: 1.4,
        };
        let mut p = StandstillProbe::new(StandstillProbeConfig {
            ts,
            amplitude: 2.2,
            period: 0.1,
            gain: 0.0,
            max_speed: 1.0,
            min_load: 1.0,
            inertia,
            swing: 0.0,
            arm_time: 0.1,
        })
        .unwrap();
        let w_s = 2.0 * core::f64::consts::PI * 5.0;
        let (kp, ki) = (c_j * w_s, c_j * w_s * w_s / 5.0);
        let (mut omega, mut integral, mut id) = (0.0, b.tau(0.0), 0.0);
        for _ in 0..3000 {
            let tau = kp * -omega + integral;
            id = p.step(true, true, tau, omega, (id, tau), flux, 0.0);
            let torque = b.torque(tau, id) / flux;
            omega += ts * (torque - b.load / flux) / c_j;
            integral += ts * ki * -omega;
        }
        p.reading()
    };
    for delta in [-0.2, 0.1, 0.3] {
        let (with, without) = (read(delta, c_j), read(delta, 0.0));
        assert!(
            (with - delta).abs() < 0.05 * delta.abs(),
            "δ {delta}: {with}"
        );
        assert!(
            (without - delta).abs() > 0.2 * delta.abs(),
            "δ {delta}: {without}"
        );
    }
}

/// The correction loop per period (module docs, "Correction"): the error x after period
/// k, the reading r_k = (x_{k−1} + x_k)/2, the turn over the next period g·r_k + ĉ_k with
/// ĉ_k = ĉ_{k−1} + h·r_k: 2z³ + (G + H − 4)·z² + (2 + H)·z − G = 0 (G = g·T_p,
/// H = h·T_p) has its triple root at p0.
#[test]
fn correction_loop_has_its_triple_pole() {
    let (g, h) = (TRIPLE_POLE_GAIN, CREEP_GAIN_RATIO * TRIPLE_POLE_GAIN);
    let z = TRIPLE_POLE;
    let f = 2.0 * z * z * z + (g + h - 4.0) * z * z + (2.0 + h) * z - g;
    let df = 6.0 * z * z + 2.0 * (g + h - 4.0) * z + 2.0 + h;
    let d2f = 12.0 * z + 2.0 * (g + h - 4.0);
    assert!(f.abs() < 1e-12 && df.abs() < 1e-12 && d2f.abs() < 1e-12);
    assert!((TRIPLE_POLE - (4f64.cbrt() - 1.0)).abs() < 1e-15);
}

/// A constant creep of θ̂ (0.5 rad/s) at a settled loaded standstill: the probe's turn
/// learns it: after 1.5 s (14 periods) the angle error stays below 5 % of the c/g a
/// proportional turn would leave.
#[test]
fn creep_is_learned_and_leaves_no_angle_error() {
    let (ts, period, creep) = (1e-3, 0.1, 0.5);
    let gain = TRIPLE_POLE_GAIN / period;
    let mut p = StandstillProbe::new(StandstillProbeConfig {
        ts,
        amplitude: 2.2,
        period,
        gain,
        max_speed: 1.0,
        min_load: 1.0,
        inertia: 0.0,
        swing: 0.0,
        arm_time: period,
    })
    .unwrap();
    let mut b = Balance {
        flux: 0.1,
        saliency: 0.0,
        delta: 0.0,
        load: 1.4,
    };
    let mut id = 0.0;
    let mut worst_late = 0.0f64;
    for n in 0..3000 {
        let tau = b.tau(id);
        id = p.step(true, true, tau, 0.0, (id, tau), b.flux, 0.0);
        // δ = θ − θ̂: the creep turns θ̂ away, the probe's turn brings it back.
        b.delta += ts * (creep - p.rate());
        if n > 1500 {
            worst_late = worst_late.max(b.delta.abs());
        }
    }
    assert!(worst_late < 0.05 * creep / gain, "{worst_late} rad");
}

/// The arming time counts the standstill whatever the estimator's mode; the armed probe
/// starts the first sample in limiter mode and then holds when limiter mode drops (its
/// own swing of the rotor), until the standstill ends.
#[test]
fn arming_counts_the_standstill_and_the_probe_holds_out_of_limiter_mode() {
    let (tau, flux) = (14.0, 0.1);
    let mut p = probe(2.2); // arming time 0.2 s = 200 samples
    let step = |p: &mut StandstillProbe<f64>, gate: bool, limiter: bool| {
        p.step(gate, limiter, tau, 0.0, (0.0, tau), flux, 0.0)
    };
    for _ in 0..300 {
        assert_eq!(step(&mut p, true, false), 0.0);
    }
    assert!(p.gated() && !p.active(), "armed, not yet in limiter mode");
    assert_ne!(
        step(&mut p, true, true),
        0.0,
        "starts at once in limiter mode"
    );
    assert!(p.active());
    for _ in 0..50 {
        step(&mut p, true, false);
    }
    assert!(p.active(), "holds out of limiter mode");
    assert_eq!(step(&mut p, false, true), 0.0);
    assert!(!p.active() && !p.gated(), "stops with the standstill");
    // A stop shorter than the arming time never probes, even in limiter mode.
    for _ in 0..150 {
        assert_eq!(step(&mut p, true, true), 0.0);
    }
    step(&mut p, false, true);
    for _ in 0..150 {
        assert_eq!(step(&mut p, true, true), 0.0);
    }
    assert!(!p.active());
}

/// At a brake's release the probe arms after one period (0.2 s here) instead of the
/// arming time (0.5 s), and keeps probing once started; a speed reference that leaves
/// the standstill before it starts ends the short arming.
#[test]
fn a_brake_release_arms_the_probe_after_one_period() {
    let (tau, flux) = (14.0, 0.1);
    let config = StandstillProbeConfig {
        arm_time: 0.5,
        ..probe(2.2).config
    };
    let step = |p: &mut StandstillProbe<f64>| p.step(true, true, tau, 0.0, (0.0, tau), flux, 0.0);
    let mut p = StandstillProbe::new(config).unwrap();
    p.arm_at_release();
    p.leave_release(0.5); // within the standstill's speed bound (1 rad/s)
    for _ in 0..200 {
        assert_eq!(step(&mut p), 0.0);
    }
    assert_ne!(step(&mut p), 0.0, "armed after one period");
    assert!(p.active());
    let probed = (0..1000).filter(|_| step(&mut p) != 0.0).count();
    assert!(p.active() && probed > 500, "{probed}");
    // Left before it started: the arming time again.
    let mut q = StandstillProbe::new(config).unwrap();
    q.arm_at_release();
    q.leave_release(2.0);
    for _ in 0..400 {
        assert_eq!(step(&mut q), 0.0);
    }
    assert!(!q.active());
}

/// A release hold slower than the period (ω_h = 8.5 rad/s, the drawn 116 kW IPMSM of
/// 25 kg·m²: its catch (2 + √2)/ω_h = 0.40 s) holds the release's arming for the catch
/// instead of one period (0.2 s here); a hold faster than the period (ω_h = 37.7 rad/s, the
/// hub motor's: 0.09 s) keeps one period, and a non-finite ω_h one period too.
#[test]
fn a_slow_release_hold_arms_the_probe_after_its_catch() {
    let (tau, flux) = (14.0, 0.1);
    let config = StandstillProbeConfig {
        arm_time: 0.5,
        ..probe(2.2).config
    };
    let step = |p: &mut StandstillProbe<f64>| p.step(true, true, tau, 0.0, (0.0, tau), flux, 0.0);
    // Samples of silence after a release before the probe's first Δi_d.
    let silent = |omega_h: f64| {
        let mut p = StandstillProbe::new(config).unwrap();
        p.set_release_catch(omega_h);
        p.arm_at_release();
        (0..2000).take_while(|_| step(&mut p) == 0.0).count()
    };
    assert_eq!(silent(8.5), 402, "(2 + √2)/8.5 s at 1 ms");
    assert_eq!(silent(37.7), 200, "one period");
    assert_eq!(silent(f64::NAN), 200, "one period");
    assert_eq!(silent(0.0), 200, "one period");
}

/// The amplitude follows the rotor's answer ([`amplitude`]): a light rotor, whose speed
/// answers the probe's torque through the angle error (a first-order speed loop of 10 Hz
/// around ω̇ = k·Δi_d), swings to 4.3 times the bound at the configured amplitude; with the
/// bound the amplitude settles where the swing's peak is the bound (measured: 0.23 of the
/// configured amplitude). A rotor ten times heavier, whose swing stays within the bound
/// (0.43 of it), keeps the configured amplitude, as does the light one without a bound.
#[test]
fn the_amplitude_shrinks_where_the_rotor_follows_the_probe() {
    let (tau, flux, bound) = (14.0, 0.1, 2.0);
    // (final amplitude, the last period's largest |ω|)
    let run = |k: f64, swing: f64| {
        let mut p = StandstillProbe::new(StandstillProbeConfig {
            swing,
            ..probe(2.2).config
        })
        .unwrap();
        let (mut omega, mut peak) = (0.0f64, 0.0f64);
        for i in 0..200 + 30 * 200 {
            let did = p.step(true, true, tau, omega, (0.0, tau), flux, 0.0);
            omega += 1e-3 * (k * did - 2.0 * core::f64::consts::PI * 10.0 * omega);
            peak = if i % 200 == 0 {
                0.0
            } else {
                peak.max(omega.abs())
            };
        }
        assert!(p.active());
        (p.amplitude, peak)
    };
    let (free_a, free_peak) = run(250.0, 0.0);
    assert_eq!(free_a, 2.2);
    assert!(free_peak > 4.0 * bound, "{free_peak}");
    let (a, peak) = run(250.0, bound);
    assert!(
        a < 0.3 * 2.2 && a > 0.15 * 2.2,
        "a {a} peak {peak} free {free_peak}"
    );
    assert!((peak - bound).abs() < 0.05 * bound, "{peak}");
    let (heavy_a, heavy_peak) = run(25.0, bound);
    assert_eq!(heavy_a, 2.2, "{heavy_peak}");
}
