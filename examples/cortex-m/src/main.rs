//! fado's f32 estimator in a 10 kHz interrupt on a Cortex-M4F: the firmware user's starting
//! point, and the image `scripts/firmware-cost.sh` measures.
//!
//! `main` configures SysTick for 10 kHz, builds the estimator's parameters once
//! ([`EstimatorParams`], one set per scenario kind) into a write-once `static`, and for each
//! scenario hands a fresh [`EstimatorState`] to the interrupt. The SysTick handler stands in for the
//! PWM/ADC interrupt of a drive: it reads the "ADC" (here a generated machine signal: an ideal
//! PMSM at i_d = 0, the paper's surface-magnet motor or a salient IPMSM, turning at a speed that
//! ramps up and then holds), runs one estimator step and
//! keeps the worst angle error of the last samples. Results are printed over semihosting, and
//! the program exits with status 0 when every scenario kept lock (QEMU passes the status on).
//!
//! # Sharing the estimator with the interrupt (static-init pattern)
//! The estimator is two records (docs/results/firmware-cost.md): its parameters, every
//! constant of the step, immutable once built, and its state, what the step changes.
//!
//! - The parameters are built (and the configuration checked) once in `main`, outside the
//!   interrupt, and stored in `static PARAMS: Mutex<OnceCell<…>>`: written once before the
//!   interrupt runs, read-only afterwards. `EstimatorParams::new` cannot be a `const fn` (the
//!   checks and the derived gains call the generic `Real` trait's methods — √, eˣ, the
//!   tracker gains — which stable Rust does not allow in a `const fn`), so a `static`
//!   initialised at run time is the pattern; the step borrows it, so the parameters are never
//!   copied into the state.
//! - The state (`size_of` printed below, ≤ 256 B) lives in the interrupt's
//!   `static Mutex<RefCell<Option<App>>>`, borrowed with `try_borrow_mut`.
//!
//! Nothing on the interrupt's path can panic: an unset `OnceCell`, `Option::None` or a
//! failed borrow simply skip the sample. No `unsafe`, no allocation, and the configuration
//! validation (which the interrupt never needs) stays out of the interrupt's code.
//!
//! The cost script finds the step as the out-of-line function [`estimator_step`] (the split
//! step, `EstimatorState::step_lean` with the borrowed parameters) and counts the
//! instructions executed from its entry to its return.

#![no_std]
#![no_main]

mod drive_loop;
mod flux_lookup;
mod paper_kernel;

use core::cell::{Cell, OnceCell, RefCell};
use core::f32::consts::TAU;
use core::panic::PanicInfo;

use cortex_m::interrupt::{self, Mutex};
use cortex_m::peripheral::syst::SystClkSource;
use cortex_m_rt::{entry, exception};
use cortex_m_semihosting::{debug, hprintln};
use drive_loop::DriveApp;
use fado_core::magnetics::MagneticModel;
use fado_core::{
    Ab, Abc, Dq, DriveOutput, Estimate, EstimatorConfig, EstimatorParams, EstimatorState,
    EstimatorTuning, LeanEstimate, MachineMagnetics, MachineModel, Mode, SensorlessDrive,
    SensorlessEstimator,
};
use paper_kernel::{PaperKernel, paper_kernel_held_step, paper_kernel_step};

/// QEMU's MPS2 system clock (25 MHz), which clocks SysTick.
const SYSCLK_HZ: u32 = 25_000_000;
/// The estimator's sampling frequency (paper, section V).
const SAMPLE_HZ: u32 = 10_000;
/// Sampling period in s.
const TS: f32 = 1.0 / SAMPLE_HZ as f32;

/// q-axis current of the generated operating point as a fraction of the rated current.
const IQ_RATIO: f32 = 0.4;

/// One measured operating point.
#[derive(Clone, Copy)]
struct Scenario {
    name: &'static str,
    /// Final electrical speed (Hz).
    speed_hz: f32,
    /// Ramp time from standstill to `speed_hz` (s): slow enough for T2S-1 to stay locked.
    ramp_s: f32,
    /// Samples held at `speed_hz` after the ramp.
    hold_samples: u32,
    /// Which of [`PARAMS`]: [`ADAPTIVE`], [`FIXED_RS`], [`PAPER_PATH`] or [`PAPER_PATH_HELD`].
    params: usize,
    /// Also step the paper's estimator alone ([`paper_kernel`]) on the same samples, and
    /// check that it gives fado's angle (with [`PAPER_PATH`]).
    kernel: bool,
    /// The generated machine and the estimator's model: the paper's surface-magnet motor
    /// (false) or the salient [`ipmsm_2k2`] (true).
    salient: bool,
}

/// Index in [`PARAMS`]: the default configuration (R̂s adaptation on).
const ADAPTIVE: usize = 0;
/// The default configuration with the paper's fixed R̂s (`rs_adaptation = false`).
const FIXED_RS: usize = 1;
/// The paper's path: fixed R̂s, and fado's other additions to the method that a switch turns
/// off (`observer.lag_compensation`, `observer.on_rotor_flux`, `limiter.recentring` false,
/// `observer.gain_period` 0).
const PAPER_PATH: usize = 2;
/// The paper's path with the observer's gains held as fado holds them by default
/// (`observer.gain_period` 0.4 ms): the kernel beside it is [`paper_kernel_held_step`].
const PAPER_PATH_HELD: usize = 3;
/// The default configuration (R̂s adaptation on) for the salient [`ipmsm_2k2`]: the step with
/// the active-flux terms of a salient rotor, which the paper's motor (Ld = Lq) never runs.
const SALIENT: usize = 4;
/// The default configuration for [`ipmsm_2k2_map`]: the step of a saturating model, its
/// active flux from the 16 × 16 uniform-grid flux table in flash.
const SATURATING_MAP: usize = 5;

/// The 2.2 kW interior-magnet motor of `motors/ipmsm-2k2.toml` (motulator's example motor,
/// Lq/Ld 1.42): a salient rotor, whose active-flux terms cost cycles the paper's motor does
/// not show. Rated 1500 r/min with 3 pole pairs, i.e. 75 Hz electrical.
fn ipmsm_2k2() -> MachineModel<f32> {
    MachineModel {
        rs: 3.6,
        ld: 0.036,
        lq: 0.051,
        flux_linkage: 0.545,
        pole_pairs: 3,
        inertia: 0.015,
        viscous_friction: 8.9e-4,
        rated_current: 6.08,
        rated_speed_rpm: 1500.0,
        rated_torque: 14.0,
        dc_voltage: 540.0,
        magnetics: MachineMagnetics::Linear,
    }
}

/// [`ipmsm_2k2`] saturating: its magnetics the 16 × 16 flux map in flash as a uniform-grid
/// table ([`flux_lookup::UNIFORM_MAP`], q self-saturation and cross-saturation), the constant
/// fields the map's values at zero current.
fn ipmsm_2k2_map() -> MachineModel<f32> {
    MachineModel {
        magnetics: MachineMagnetics::Uniform(&flux_lookup::UNIFORM_MAP),
        ..ipmsm_2k2()
    }
}

/// The generated machine and the estimator's model of scenario `s`.
fn model_of(s: &Scenario) -> MachineModel<f32> {
    if s.params == SATURATING_MAP {
        ipmsm_2k2_map()
    } else if s.salient {
        ipmsm_2k2()
    } else {
        MachineModel::paper()
    }
}

/// Largest |θ̂_kernel − θ̂_fado| allowed between the paper's kernel and fado's paper's path
/// (rad): the `f32` rounding level (measured: 0, the two compute the same operations in the same
/// order, see `paper_kernel`). Method differences give 1e-3 rad and more: the paper's path and
/// fado's default fixed-R̂s path differ by 2e-2 rad here.
const KERNEL_TOLERANCE: f32 = 1e-4;

const SCENARIOS: [Scenario; 12] = [
    Scenario {
        name: "low speed, R^s adaptation",
        speed_hz: 19.5,
        ramp_s: 0.05,
        hold_samples: 1000,
        params: ADAPTIVE,
        kernel: false,
        salient: false,
    },
    Scenario {
        name: "high speed, R^s adaptation",
        speed_hz: 700.0,
        ramp_s: 0.4,
        hold_samples: 1000,
        params: ADAPTIVE,
        kernel: false,
        salient: false,
    },
    Scenario {
        name: "low speed, fixed R^s (paper)",
        speed_hz: 19.5,
        ramp_s: 0.05,
        hold_samples: 1000,
        params: FIXED_RS,
        kernel: false,
        salient: false,
    },
    Scenario {
        name: "high speed, fixed R^s (paper)",
        speed_hz: 700.0,
        ramp_s: 0.4,
        hold_samples: 1000,
        params: FIXED_RS,
        kernel: false,
        salient: false,
    },
    Scenario {
        name: "low speed, paper's path (fado and the paper's kernel)",
        speed_hz: 19.5,
        ramp_s: 0.05,
        hold_samples: 1000,
        params: PAPER_PATH,
        kernel: true,
        salient: false,
    },
    Scenario {
        name: "high speed, paper's path (fado and the paper's kernel)",
        speed_hz: 700.0,
        ramp_s: 0.4,
        hold_samples: 1000,
        params: PAPER_PATH,
        kernel: true,
        salient: false,
    },
    Scenario {
        name: "low speed, paper's path, gains held (fado and the paper's kernel)",
        speed_hz: 19.5,
        ramp_s: 0.05,
        hold_samples: 1000,
        params: PAPER_PATH_HELD,
        kernel: true,
        salient: false,
    },
    Scenario {
        name: "high speed, paper's path, gains held (fado and the paper's kernel)",
        speed_hz: 700.0,
        ramp_s: 0.4,
        hold_samples: 1000,
        params: PAPER_PATH_HELD,
        kernel: true,
        salient: false,
    },
    Scenario {
        name: "low speed, R^s adaptation, salient ipmsm-2k2",
        speed_hz: 19.5,
        ramp_s: 0.05,
        hold_samples: 1000,
        params: SALIENT,
        kernel: false,
        salient: true,
    },
    Scenario {
        name: "rated speed, R^s adaptation, salient ipmsm-2k2",
        speed_hz: 75.0,
        ramp_s: 0.2,
        hold_samples: 1000,
        params: SALIENT,
        kernel: false,
        salient: true,
    },
    Scenario {
        name: "low speed, R^s adaptation, ipmsm-2k2 saturating, 16 x 16 uniform flux table in flash",
        speed_hz: 19.5,
        ramp_s: 0.05,
        hold_samples: 1000,
        params: SATURATING_MAP,
        kernel: false,
        salient: true,
    },
    Scenario {
        name: "rated speed, R^s adaptation, ipmsm-2k2 saturating, 16 x 16 uniform flux table in flash",
        speed_hz: 75.0,
        ramp_s: 0.2,
        hold_samples: 1000,
        params: SATURATING_MAP,
        kernel: false,
        salient: true,
    },
];

/// The generated machine: angle and speed of an ideal PMSM, its flux and current. Its data are
/// the scenario's motor ([`model_of`]: the paper's, section V, or [`ipmsm_2k2`]), the same model
/// the estimator is configured with. The current is on the q axis (i_d = 0), so the stator flux
/// (λf + j·Lq·iq)·e^{jθ} is exact for a salient rotor too (Ld multiplies i_d = 0).
struct Machine {
    rs: f32,
    lq: f32,
    flux_linkage: f32,
    /// A saturating model's ψ(0, i_q) (the current is constant in the rotor frame), used
    /// instead of (λf, Lq·i_q).
    flux_dq: Option<Dq<f32>>,
    iq: f32,
    theta: f32,
    omega: f32,
    /// Speed increment per sample during the ramp (rad/s).
    d_omega: f32,
    omega_final: f32,
    flux: Ab<f32>,
    current: Ab<f32>,
}

impl Machine {
    fn new(s: &Scenario, model: &MachineModel<f32>) -> Self {
        let omega_final = TAU * s.speed_hz;
        let iq = IQ_RATIO * model.rated_current;
        let mut m = Self {
            rs: model.rs,
            lq: model.lq,
            flux_linkage: model.flux_linkage,
            flux_dq: match model.magnetics {
                MachineMagnetics::Linear => None,
                _ => Some(model.magnetic_model().flux(Dq::new(0.0, iq))),
            },
            iq,
            theta: 0.0,
            omega: 0.0,
            d_omega: omega_final * TS / s.ramp_s,
            omega_final,
            flux: Ab::new(0.0, 0.0),
            current: Ab::new(0.0, 0.0),
        };
        (m.flux, m.current) = m.flux_and_current();
        m
    }

    /// Stator flux λ = (λf + j·Lq·iq)·e^{jθ} and current j·iq·e^{jθ} at the present angle.
    fn flux_and_current(&self) -> (Ab<f32>, Ab<f32>) {
        let unit = Ab::new(cos(self.theta), sin(self.theta));
        let i = unit.mul_j() * self.iq;
        match self.flux_dq {
            Some(psi) => (unit * psi.d + unit.mul_j() * psi.q, i),
            None => (unit * self.flux_linkage + i * self.lq, i),
        }
    }

    /// Advances one sample; returns (the average voltage over the interval, the current now).
    fn sample(&mut self) -> (Ab<f32>, Ab<f32>) {
        self.omega = (self.omega + self.d_omega).min(self.omega_final);
        self.theta += self.omega * TS;
        if self.theta > core::f32::consts::PI {
            self.theta -= TAU;
        }
        let (flux, current) = self.flux_and_current();
        // v = Rs·i + dλ/dt, averaged over the interval exactly for the flux term.
        let v = (self.current + current) * (0.5 * self.rs) + (flux - self.flux) * (1.0 / TS);
        self.flux = flux;
        self.current = current;
        (v, current)
    }
}

/// sin on [−π, π] for the signal generator (not the estimator): a degree-11 odd Taylor
/// polynomial after folding into [−π/2, π/2], error below 1e-6 — plenty for a test signal.
fn sin(x: f32) -> f32 {
    let half_pi = core::f32::consts::FRAC_PI_2;
    let x = if x > half_pi {
        core::f32::consts::PI - x
    } else if x < -half_pi {
        -core::f32::consts::PI - x
    } else {
        x
    };
    let x2 = x * x;
    x * (1.0
        + x2 * (-1.0 / 6.0
            + x2 * (1.0 / 120.0
                + x2 * (-1.0 / 5040.0 + x2 * (1.0 / 362_880.0 - x2 / 39_916_800.0)))))
}

fn cos(x: f32) -> f32 {
    let shifted = x + core::f32::consts::FRAC_PI_2;
    sin(if shifted > core::f32::consts::PI {
        shifted - TAU
    } else {
        shifted
    })
}

/// Everything the interrupt owns.
struct App {
    /// Which of [`PARAMS`] the state was made for.
    params: usize,
    state: EstimatorState<f32>,
    machine: Machine,
    samples: u32,
    total_samples: u32,
    /// Worst |θ̂ − θ| (rad) over the last `hold_samples / 2` samples.
    worst_error: f32,
    rejected: u32,
    done: bool,
    /// The paper's estimator alone, stepped on the same samples ([`Scenario::kernel`]).
    kernel: Option<PaperKernel>,
    /// Largest |θ̂_kernel − θ̂_fado| over all samples (rad).
    kernel_diff: f32,
    /// Largest |ω̂_kernel − ω̂_fado| of T2S-1 and T2S-2 over all samples (rad/s), and the
    /// number of samples whose mode differs.
    kernel_omega_diff: f32,
    kernel_mode_diff: u32,
    /// The kernel's worst |θ̂ − θ| over the last `hold_samples / 2` samples.
    kernel_worst: f32,
    /// The saturating scenarios' state stepped beside [`App::state`] on the same samples by
    /// [`estimator_step`] (the machine record's model, matched at run time), and the number
    /// of samples whose estimate differs from [`estimator_step_table`]'s (none: the same step).
    record: Option<EstimatorState<f32>>,
    record_diffs: u32,
}

static APP: Mutex<RefCell<Option<App>>> = Mutex::new(RefCell::new(None));

/// The whole drive around a simulated motor ([`drive_loop`]), run after the estimator's
/// scenarios.
static DRIVE: Mutex<RefCell<Option<DriveApp>>> = Mutex::new(RefCell::new(None));

/// The estimator's parameters, written once by `main` before the interrupt runs (index 0 with
/// the default R̂s adaptation, 1 with the paper's fixed R̂s, 2 the paper's path and 3 the same
/// with the gains held, 4 the default on a salient motor, 5 on a saturating one: see
/// [`PAPER_PATH`], [`PAPER_PATH_HELD`], [`SALIENT`], [`SATURATING_MAP`]); read-only afterwards.
static PARAMS: Mutex<OnceCell<[EstimatorParams<f32>; 6]>> = Mutex::new(OnceCell::new());

/// Lowest stack pointer seen just before calling [`estimator_step`] or [`drive_step`] (stack
/// measurement).
static STEP_SP: Mutex<Cell<u32>> = Mutex::new(Cell::new(u32::MAX));

/// Records the stack pointer just before a measured step ([`estimator_step`] or
/// [`drive_step`]) is called, for the depth below the step's caller.
fn note_step_sp() {
    let sp = cortex_m::register::msp::read();
    interrupt::free(|cs| {
        let cell = STEP_SP.borrow(cs);
        cell.set(cell.get().min(sp));
    });
}

/// How much stack below the present stack pointer is painted and checked.
const PAINTED: u32 = 8 * 1024;
/// The paint: any word the program writes differs from it in practice.
const PAINT: u32 = 0xA5C3_5A3C;

/// Paints `PAINTED` bytes below the stack pointer (less a margin for this function's own
/// frame) and returns the stack pointer. Measurement only: not part of a firmware.
#[inline(never)]
fn paint_stack() -> u32 {
    let sp = cortex_m::register::msp::read();
    let top = (sp - 64) & !3;
    let mut a = top - PAINTED;
    while a < top {
        // SAFETY: RAM below the live stack pointer, within the 4 MiB RAM region, unused.
        unsafe { core::ptr::write_volatile(a as *mut u32, PAINT) };
        a += 4;
    }
    interrupt::free(|cs| STEP_SP.borrow(cs).set(u32::MAX));
    sp
}

/// The lowest address whose paint was overwritten since [`paint_stack`].
#[inline(never)]
fn lowest_touched_stack() -> u32 {
    let sp = cortex_m::register::msp::read();
    let top = (sp - 64) & !3;
    let mut a = top - PAINTED;
    while a < top {
        // SAFETY: as in `paint_stack`.
        if unsafe { core::ptr::read_volatile(a as *const u32) } != PAINT {
            return a;
        }
        a += 4;
    }
    top
}

/// One estimator step, out of line: the unit the cost script measures. Firmware uses
/// `step_lean` (θ̂, ω̂, mode, lock, fault flag) on its state with the borrowed parameters;
/// `step` also returns the diagnostics of `Estimate` (λ1, D̂, λ̂r, θm, …), about 65 cycles
/// more (docs/results/firmware-cost.md), and `EstimatorState::last` recomputes them for the last sample
/// when a debugger or a telemetry task wants them. (`SensorlessEstimator`, the owner of both
/// records, steps identically: `split_step_is_the_owners_step` in fado-core.)
#[inline(never)]
#[unsafe(no_mangle)]
pub fn estimator_step(
    params: &EstimatorParams<f32>,
    state: &mut EstimatorState<f32>,
    v_ab: Ab<f32>,
    i_ab: Ab<f32>,
) -> LeanEstimate<f32> {
    state.step_lean(params, v_ab, i_ab)
}

/// One estimator step of the saturating scenarios, out of line: `step_lean_in` with the
/// machine's map named by its type (the 16 × 16 table in flash that the parameters' machine
/// borrows, [`flux_lookup::UNIFORM`]), so that the step is compiled for that table: what a
/// firmware whose map is known when it is built runs. The same estimate as
/// [`estimator_step`] on the same parameters (the record's model, matched at run time).
#[inline(never)]
#[unsafe(no_mangle)]
pub fn estimator_step_table(
    params: &EstimatorParams<f32>,
    state: &mut EstimatorState<f32>,
    v_ab: Ab<f32>,
    i_ab: Ab<f32>,
) -> LeanEstimate<f32> {
    state.step_lean_in(params, &flux_lookup::UNIFORM, v_ab, i_ab)
}

/// One drive step (Clarke/Park, current and speed control, the estimator, modulation),
/// out of line: the CI gate (`scripts/check-firmware-symbols.sh`) checks the code reachable
/// from it as it checks the interrupt's. `main` steps a drive through it once; the
/// interrupt steps the estimator alone (a closed loop of the drive needs a plant, which this
/// image does not model).
#[inline(never)]
#[unsafe(no_mangle)]
pub fn drive_step(
    drive: &mut SensorlessDrive<f32>,
    i_abc: Abc<f32>,
    vdc: f32,
    speed_ref_mech: f32,
) -> DriveOutput<f32> {
    drive.step(i_abc, vdc, speed_ref_mech)
}

impl App {
    /// The interrupt's work for one sample, with the parameters the state was made for.
    fn on_sample(&mut self, params: &EstimatorParams<f32>) {
        if self.done {
            return;
        }
        let (v, i) = self.machine.sample();
        note_step_sp();
        let out = if self.params == SATURATING_MAP {
            estimator_step_table(params, &mut self.state, v, i)
        } else {
            estimator_step(params, &mut self.state, v, i)
        };
        if let Some(record) = self.record.as_mut()
            && estimator_step(params, record, v, i) != out
        {
            self.record_diffs += 1;
        }
        let kernel = self.kernel.as_mut().map(|k| {
            if self.samples == 0 {
                k.prime(i);
            }
            let theta = if k.holds_gains() {
                paper_kernel_held_step(k, v, i)
            } else {
                paper_kernel_step(k, v, i)
            };
            k.output(theta)
        });
        self.samples += 1;
        if let Some(k) = kernel {
            self.kernel_diff = self.kernel_diff.max(wrap(k.theta - out.theta).abs());
            self.kernel_omega_diff = self
                .kernel_omega_diff
                .max((k.omega - out.omega).abs())
                .max((k.omega_control - out.omega_control).abs());
            if k.limiter != (out.mode == Mode::Limiter) {
                self.kernel_mode_diff += 1;
            }
        }
        if out.input_fault {
            self.rejected += 1;
        }
        if self.samples > self.total_samples - self.total_samples / 8 {
            let e = wrap(out.theta - self.machine.theta);
            self.worst_error = self.worst_error.max(e.abs());
            if let Some(k) = kernel {
                self.kernel_worst = self
                    .kernel_worst
                    .max(wrap(k.theta - self.machine.theta).abs());
            }
        }
        if self.samples >= self.total_samples {
            self.done = true;
        }
    }
}

/// A difference of two angles in [−π, π], wrapped into [−π, π].
fn wrap(e: f32) -> f32 {
    if e > core::f32::consts::PI {
        e - TAU
    } else if e < -core::f32::consts::PI {
        e + TAU
    } else {
        e
    }
}

#[exception]
fn SysTick() {
    interrupt::free(|cs| {
        if let Some(params) = PARAMS.borrow(cs).get()
            && let Ok(mut app) = APP.borrow(cs).try_borrow_mut()
            && let Some(app) = app.as_mut()
            && let Some(params) = params.get(app.params)
        {
            app.on_sample(params);
        }
        drive_sample(cs);
    });
}

/// The drive scenario's share of the interrupt, out of line: its larger frame is then not
/// allocated on the estimator scenarios' interrupts (their stack figure is the estimator's).
#[inline(never)]
fn drive_sample(cs: &interrupt::CriticalSection) {
    if let Ok(mut app) = DRIVE.borrow(cs).try_borrow_mut()
        && let Some(app) = app.as_mut()
    {
        app.on_sample();
    }
}

#[entry]
fn main() -> ! {
    let Some(mut core) = cortex_m::Peripherals::take() else {
        exit(false)
    };
    core.SYST.set_clock_source(SystClkSource::Core);
    core.SYST.set_reload(SYSCLK_HZ / SAMPLE_HZ - 1);
    core.SYST.clear_current();
    core.SYST.enable_counter();
    core.SYST.enable_interrupt();

    {
        use core::mem::size_of;
        hprintln!(
            "size_of: EstimatorState<f32> = {} B (f64: {} B), EstimatorParams<f32> = {} B \
             (f64: {} B), SensorlessEstimator<f32> = {} B (f64: {} B), Estimate<f32> = {} B",
            size_of::<EstimatorState<f32>>(),
            size_of::<EstimatorState<f64>>(),
            size_of::<EstimatorParams<f32>>(),
            size_of::<EstimatorParams<f64>>(),
            size_of::<SensorlessEstimator<f32>>(),
            size_of::<SensorlessEstimator<f64>>(),
            size_of::<Estimate<f32>>()
        );
        hprintln!(
            "size_of: PaperKernel = {} B (constants and state of the paper's estimator alone)",
            size_of::<PaperKernel>()
        );
    }
    // The estimator's parameters, once (configuration checked here, not in the interrupt).
    let paper_config = {
        let mut config = EstimatorConfig::for_machine(&MachineModel::<f32>::paper());
        // Every fado addition that can be off, off; the gains (16) every sample, as the paper.
        config.tuning = config.tuning.paper_path();
        config
    };
    // The same with the gains held over fado's default period.
    let paper_held_config = {
        let mut config = paper_config;
        config.tuning.observer.gain_period = EstimatorTuning::default().observer.gain_period;
        config
    };
    let kernel_configs = [
        paper_config,
        paper_config,
        paper_config,
        paper_held_config,
        paper_config,
        paper_config,
    ];
    let params = {
        let model = MachineModel::<f32>::paper();
        let build = |rs_adaptation| {
            let mut config = EstimatorConfig::for_machine(&model);
            config.tuning.rs_adaptation.enabled = rs_adaptation;
            EstimatorParams::new(config)
        };
        match (
            build(true),
            build(false),
            EstimatorParams::new(paper_config),
            EstimatorParams::new(paper_held_config),
            EstimatorParams::new(EstimatorConfig::for_machine(&ipmsm_2k2())),
            EstimatorParams::new(EstimatorConfig::for_machine(&ipmsm_2k2_map())),
        ) {
            (Ok(adaptive), Ok(fixed), Ok(paper), Ok(held), Ok(salient), Ok(saturating)) => {
                [adaptive, fixed, paper, held, salient, saturating]
            }
            _ => {
                hprintln!("invalid configuration");
                exit(false)
            }
        }
    };
    if !interrupt::free(|cs| PARAMS.borrow(cs).set(params).is_ok()) {
        exit(false)
    }
    hprintln!(
        "size_of::<SensorlessDrive<f32>>() = {} B",
        core::mem::size_of::<SensorlessDrive<f32>>()
    );
    let mut all_locked = true;
    let (mut deepest_isr, mut deepest_step) = (0, 0);
    for (index, s) in SCENARIOS.iter().enumerate() {
        let model = model_of(s);
        let which = s.params;
        let state = EstimatorState::new(&params[which]);
        let machine = Machine::new(s, &model);
        let total_samples = (s.ramp_s * SAMPLE_HZ as f32) as u32 + s.hold_samples;
        let app = App {
            params: which,
            state,
            machine,
            samples: 0,
            total_samples,
            worst_error: 0.0,
            rejected: 0,
            done: false,
            kernel: s.kernel.then(|| PaperKernel::new(&kernel_configs[which])),
            kernel_diff: 0.0,
            kernel_omega_diff: 0.0,
            kernel_mode_diff: 0,
            kernel_worst: 0.0,
            record: (which == SATURATING_MAP).then_some(state),
            record_diffs: 0,
        };
        // The scenario marker the cost script splits the trace at.
        scenario_marker(index as u32);
        let idle_sp = paint_stack();
        interrupt::free(|cs| {
            if let Ok(mut slot) = APP.borrow(cs).try_borrow_mut() {
                *slot = Some(app);
            }
        });
        let (worst, rejected, samples, kernel, record_diffs) = loop {
            cortex_m::asm::wfi();
            let finished = interrupt::free(|cs| match APP.borrow(cs).try_borrow_mut() {
                Ok(mut slot) => match slot.as_mut() {
                    Some(app) if app.done => {
                        let r = (
                            app.worst_error,
                            app.rejected,
                            app.samples,
                            app.kernel.map(|_| {
                                (
                                    app.kernel_diff,
                                    app.kernel_omega_diff,
                                    app.kernel_mode_diff,
                                    app.kernel_worst,
                                )
                            }),
                            app.record.map(|_| app.record_diffs),
                        );
                        *slot = None;
                        Some(r)
                    }
                    _ => None,
                },
                Err(_) => None,
            });
            if let Some(r) = finished {
                break r;
            }
        };
        let lowest = lowest_touched_stack();
        let step_sp = interrupt::free(|cs| STEP_SP.borrow(cs).get());
        deepest_isr = deepest_isr.max(idle_sp - lowest);
        deepest_step = deepest_step.max(step_sp.saturating_sub(lowest));
        let locked = worst < 0.1 && rejected == 0 && record_diffs.is_none_or(|n| n == 0);
        all_locked &= locked;
        hprintln!(
            "scenario {}: {} at {} Hz electrical: {} samples, worst |θ̂ − θ| over the last {} = {} rad, {} rejected{}",
            index,
            s.name,
            s.speed_hz,
            samples,
            samples / 8,
            worst,
            rejected,
            if locked { "" } else { "  NOT LOCKED" }
        );
        if let Some(n) = record_diffs {
            hprintln!(
                "scenario {}: the machine record's step (estimator_step) beside estimator_step_table: {} of {} samples differ",
                index,
                n,
                samples
            );
        }
        if let Some((diff, omega_diff, mode_diff, kernel_worst)) = kernel {
            let same = diff <= KERNEL_TOLERANCE && mode_diff == 0 && kernel_worst < 0.1;
            all_locked &= same;
            hprintln!(
                "scenario {}: the paper's kernel: over all {} samples max |θ̂_kernel − θ̂_fado| = {} rad, max |ω̂_kernel − ω̂_fado| = {} rad/s, {} samples of another mode; worst |θ̂ − θ| over the last {} = {} rad{}",
                index,
                samples,
                diff,
                omega_diff,
                mode_diff,
                samples / 8,
                kernel_worst,
                if same { "" } else { "  NOT THE SAME METHOD" }
            );
        }
    }
    hprintln!(
        "deepest stack: {} B below the idle loop's stack pointer (interrupt entry with FPU \
         context included), {} B below the caller of estimator_step",
        deepest_isr,
        deepest_step
    );
    // The whole drive in the interrupt, around a simulated motor (scenario SCENARIOS.len()).
    let Some(drive_app) = DriveApp::new() else {
        hprintln!("invalid drive configuration");
        exit(false)
    };
    scenario_marker(SCENARIOS.len() as u32);
    let idle_sp = paint_stack();
    interrupt::free(|cs| {
        if let Ok(mut slot) = DRIVE.borrow(cs).try_borrow_mut() {
            *slot = Some(drive_app);
        }
    });
    let drive_result = loop {
        cortex_m::asm::wfi();
        let finished = interrupt::free(|cs| match DRIVE.borrow(cs).try_borrow_mut() {
            // The result alone leaves the cell (moving the whole `DriveApp` out would be a
            // `memcpy`, a function the drive's step shares, counted as the step's work).
            Ok(mut slot) => match slot.as_ref() {
                Some(app) if app.done => {
                    let result = app.result();
                    *slot = None;
                    Some(result)
                }
                _ => None,
            },
            Err(_) => None,
        });
        if let Some(app) = finished {
            break app;
        }
    };
    let lowest = lowest_touched_stack();
    let deepest_drive = idle_sp - lowest;
    let drive_sp = interrupt::free(|cs| STEP_SP.borrow(cs).get());
    let deepest_drive_step = drive_sp.saturating_sub(lowest);
    let r = &drive_result;
    let drive_ok = !r.tripped
        && r.input_faults == 0
        && r.worst_start < 0.25
        && r.worst_end < 0.05
        && (r.speed_rpm - drive_loop::SPEED_RPM).abs() < 0.03 * drive_loop::SPEED_RPM;
    all_locked &= drive_ok;
    hprintln!(
        "scenario {}: the whole drive (SensorlessDrive<f32>, drive_step) around a simulated paper's motor, 0 -> {} r/min, {} x rated torque: worst |θ̂ − θ| {} rad over the ramp, {} rad over the last 0.1 s, speed {} r/min, tripped {}, {} input faults; deepest stack {} B below the idle loop (with the simulated motor's frames), {} B below the caller of drive_step{}",
        SCENARIOS.len(),
        drive_loop::SPEED_RPM,
        drive_loop::LOAD_RATIO,
        r.worst_start,
        r.worst_end,
        r.speed_rpm,
        r.tripped,
        r.input_faults,
        deepest_drive,
        deepest_drive_step,
        if drive_ok { "" } else { "  FAILED" }
    );
    // A 16 x 16 flux map's lookups and inverses (scenario SCENARIOS.len() + 1).
    scenario_marker(SCENARIOS.len() as u32 + 1);
    match flux_lookup::run(300) {
        Some(worst) if worst < 1e-3 => hprintln!(
            "scenario {}: a 16 x 16 flux map in flash: 300 lookups ψ(i) and inverses i(ψ), worst round trip |i(ψ(i)) − i| {} A",
            SCENARIOS.len() + 1,
            worst
        ),
        other => {
            hprintln!("flux map round trip FAILED: {:?}", other);
            all_locked = false;
        }
    }
    scenario_marker(u32::MAX);
    exit(all_locked)
}

/// A no-op the cost script sees in the instruction trace: it separates the scenarios.
#[inline(never)]
#[unsafe(no_mangle)]
pub fn scenario_marker(index: u32) {
    core::hint::black_box(index);
}

fn exit(success: bool) -> ! {
    debug::exit(if success {
        debug::EXIT_SUCCESS
    } else {
        debug::EXIT_FAILURE
    });
    loop {
        cortex_m::asm::wfi();
    }
}

/// Nothing on the interrupt's path panics (the CI check proves it); anything else halts.
#[panic_handler]
fn panic(_: &PanicInfo) -> ! {
    exit(false)
}
