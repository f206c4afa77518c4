//! fado's sensorless drive on ST's B-G431B-ESC1 motor-control board.
//!
//! The board: an STM32G431CB (Cortex-M4F with FPU, run here at 170 MHz from its internal
//! oscillator), three half bridges (L6387 drivers, STL180N6F7 MOSFETs) driven by TIM1's three
//! complementary channel pairs, a shunt of 3 mΩ under each low-side switch amplified by the
//! MCU's own op-amps (PGA with external bias, an effective gain of −9.14), the DC link divided
//! by 10.4 into ADC1, and a potentiometer. Pins and gains from ST's user manual UM2516 and the
//! board's schematic:
//!
//! | function | pin |
//! |---|---|
//! | phase U, V, W high side (TIM1_CH1..3) | PA8, PA9, PA10 |
//! | phase U, V, W low side (TIM1_CH1N..3N) | PC13, PA12, PB15 |
//! | current U (OPAMP1 VINP, VINM) | PA1, PA3 |
//! | current V (OPAMP2 VINP, VINM) | PA7, PA5 |
//! | current W (OPAMP3 VINP, VINM) | PB0, PB2 |
//! | DC link (ADC1_IN1) | PA0 |
//! | potentiometer (ADC1_IN11) | PB12 |
//!
//! The program: `main` sets the clocks, the centre-aligned 20 kHz PWM with dead time, the
//! op-amps and ADCs, builds the drive from the motor's data ([`motor`]) — the configuration is
//! checked here, never in the interrupt — and hands everything to the TIM1 update interrupt.
//! The interrupt runs once per PWM period (repetition counter 1); it must fall at the
//! counter's top, where the low-side switches conduct and the shunts carry the phase currents
//! (check it on a scope before connecting a motor: which end of the period the first update
//! takes depends on how the counter starts). It converts the three currents, the DC
//! link and the potentiometer, steps the drive (`SensorlessDrive::step`: offset and gain
//! calibration, alignment, then sensorless speed control) and loads the duty cycles it returns
//! for the next period. The potentiometer sets the speed reference between −1 and +1 × the
//! rated speed.
//!
//! Kept simple on purpose, and to be adapted before a motor is connected: the conversions are
//! software-started in the interrupt (a production drive triggers injected conversions from
//! TIM1's TRGO2 so that they sample at the exact centre), there is no over-current comparator
//! break input, and the motor is the 14-pole outrunner of the guide's datasheet example.
//! Built for `thumbv7em-none-eabihf` in CI (`bash scripts/board-build.sh`); not run here.

#![no_std]
#![no_main]

use core::cell::RefCell;
use core::panic::PanicInfo;

use cortex_m::interrupt::Mutex;
use cortex_m_rt::entry;
use fado_core::{
    Abc, DriveConfig, EstimatorTuning, MachineMagnetics, MachineModel, SensorlessDrive,
};
use hal::adc::config::{AdcConfig, SampleTime};
use hal::adc::{Adc, AdcClaim, AdcCommonExt, Configured};
use hal::gpio::{Analog, gpioa::PA0, gpiob::PB12};
use hal::opamp::{Gain, InternalOutput, IntoPga, Opamp1, Opamp2, Opamp3, Pga};
use hal::prelude::*;
use hal::pwm::{ActiveHigh, C1, C2, C3, ComplementaryEnabled, Pwm, PwmAdvExt};
use hal::pwr::PwrExt;
use hal::rcc::{Config, PllConfig, PllMDiv, PllNMul, PllRDiv, PllSrc};
use hal::stm32::{self, ADC1, ADC2, TIM1, interrupt};
use hal::time::{ExtU32, RateExtU32};
use stm32g4xx_hal as hal;

/// PWM carrier frequency, Hz. The drive samples once per period (at the counter's top).
const PWM_HZ: u32 = 20_000;
/// Dead time between complementary edges, ns (the L6387 adds its own ~320 ns).
const DEAD_TIME_NS: u32 = 500;
/// Phase current per volt at the ADC, A/V: 1 / (3 mΩ × −9.14).
const AMPS_PER_VOLT: f32 = -1.0 / (0.003 * 9.14);
/// Op-amp output for zero current, V (the drive's offset calibration removes what is left).
const CURRENT_BIAS_V: f32 = 1.65;
/// DC-link volts per volt at the ADC: (18 kΩ + 169 kΩ) / 18 kΩ.
const VBUS_PER_VOLT: f32 = 187.0 / 18.0;

/// The motor: the 14-pole outrunner entered from its datasheet in docs/guide/your-motor.md.
/// Replace with yours (SI units, peak amperes; every default of the drive is a ratio of these).
fn motor() -> MachineModel<f32> {
    MachineModel {
        rs: 0.06,
        ld: 30e-6,
        lq: 30e-6,
        flux_linkage: 7.88e-3,
        pole_pairs: 7,
        inertia: 5e-4,
        viscous_friction: 1.2e-4,
        rated_current: 28.3,
        rated_speed_rpm: 1800.0,
        rated_torque: 2.34,
        dc_voltage: 24.0,
        magnetics: MachineMagnetics::Linear,
    }
}

type Phase<CH> = Pwm<TIM1, CH, ComplementaryEnabled, ActiveHigh, ActiveHigh>;

/// Everything the interrupt owns.
struct Board {
    drive: SensorlessDrive<f32>,
    adc1: Adc<ADC1, Configured>,
    adc2: Adc<ADC2, Configured>,
    current_u: Pga<Opamp1, hal::gpio::gpioa::PA1<Analog>, InternalOutput>,
    current_v: Pga<Opamp2, hal::gpio::gpioa::PA7<Analog>, InternalOutput>,
    current_w: Pga<Opamp3, hal::gpio::gpiob::PB0<Analog>, InternalOutput>,
    vbus: PA0<Analog>,
    pot: PB12<Analog>,
    phases: (Phase<C1>, Phase<C2>, Phase<C3>),
    max_duty: u16,
    rated_speed: f32,
}

static BOARD: Mutex<RefCell<Option<Board>>> = Mutex::new(RefCell::new(None));

#[entry]
fn main() -> ! {
    let dp = stm32::Peripherals::take().expect("taken once");
    let cp = cortex_m::Peripherals::take().expect("taken once");

    // 170 MHz: HSI 16 MHz / 4 × 85 / 2, with the core's boost mode.
    let pll = PllConfig {
        mux: PllSrc::HSI,
        m: PllMDiv::DIV_4,
        n: PllNMul::MUL_85,
        r: Some(PllRDiv::DIV_2),
        q: None,
        p: None,
    };
    let pwr = dp.PWR.constrain().freeze();
    let mut rcc = dp.RCC.freeze(Config::pll().pll_cfg(pll).boost(true), pwr);
    let mut delay = cp.SYST.delay(&rcc.clocks);

    let gpioa = dp.GPIOA.split(&mut rcc);
    let gpiob = dp.GPIOB.split(&mut rcc);
    let gpioc = dp.GPIOC.split(&mut rcc);

    // Centre-aligned complementary PWM with dead time; outputs stay off until enabled.
    let (_control, (c1, c2, c3)) = dp
        .TIM1
        .pwm_advanced(
            (
                gpioa.pa8.into_alternate(),
                gpioa.pa9.into_alternate(),
                gpioa.pa10.into_alternate(),
            ),
            &mut rcc,
        )
        .frequency(PWM_HZ.Hz())
        .center_aligned()
        .with_deadtime(DEAD_TIME_NS.nanos())
        .finalize();
    let phases = (
        c1.into_complementary(gpioc.pc13.into_alternate()),
        c2.into_complementary(gpioa.pa12.into_alternate()),
        c3.into_complementary(gpiob.pb15.into_alternate()),
    );
    let max_duty = phases.0.max_duty_cycle();

    // The shunt amplifiers: PGA ×16 with the board's external bias network on VINM.
    let (op1, op2, op3, ..) = dp.OPAMP.split(&mut rcc);
    let current_u = op1.pga_external_bias(
        gpioa.pa1.into_analog(),
        gpioa.pa3.into_analog(),
        Gain::Gain16,
    );
    let current_v = op2.pga_external_bias(
        gpioa.pa7.into_analog(),
        gpioa.pa5.into_analog(),
        Gain::Gain16,
    );
    let current_w = op3.pga_external_bias(
        gpiob.pb0.into_analog(),
        gpiob.pb2.into_analog(),
        Gain::Gain16,
    );

    let adc12 = dp.ADC12_COMMON.claim(Default::default(), &mut rcc);
    let adc1 = adc12.claim_and_configure(dp.ADC1, AdcConfig::default(), &mut delay);
    let adc2 = adc12.claim_and_configure(dp.ADC2, AdcConfig::default(), &mut delay);

    // The drive: every default derived from the motor's ratings, sampled once per period.
    let model = motor();
    let mut config = DriveConfig::for_machine(&model);
    config.ts = 1.0 / PWM_HZ as f32;
    config.tuning.inverter.switching_frequency = PWM_HZ as f32;
    config.tuning.inverter.dead_time = DEAD_TIME_NS as f32 * 1e-9;
    let Ok(drive) = SensorlessDrive::new(config, EstimatorTuning::default()) else {
        panic!("the motor data or the tuning were refused");
    };

    let rated_speed = model.rated_speed_rpm * core::f32::consts::TAU / 60.0;
    cortex_m::interrupt::free(|cs| {
        BOARD.borrow(cs).replace(Some(Board {
            drive,
            adc1,
            adc2,
            current_u,
            current_v,
            current_w,
            vbus: gpioa.pa0.into_analog(),
            pot: gpiob.pb12.into_analog(),
            phases,
            max_duty,
            rated_speed,
        }));
    });
    enable_update_interrupt();
    loop {
        cortex_m::asm::wfi();
    }
}

/// TIM1's update event once per period (repetition counter 1), and its interrupt unmasked. The HAL's PWM builder has no interrupt API, so two registers are
/// written directly.
fn enable_update_interrupt() {
    // SAFETY: TIM1 is owned by the PWM channels, which never touch RCR or DIER; the NVIC is
    // unmasked after the interrupt's state is in place.
    unsafe {
        let tim1 = &*TIM1::ptr();
        tim1.rcr().write(|w| w.rep().bits(1));
        tim1.dier().modify(|_, w| w.uie().set_bit());
        cortex_m::peripheral::NVIC::unmask(interrupt::TIM1_UP_TIM16);
    }
}

fn volts(adc: &Adc<impl hal::adc::Instance, Configured>, sample: u16) -> f32 {
    f32::from(adc.sample_to_millivolts(sample)) * 1e-3
}

#[interrupt]
fn TIM1_UP_TIM16() {
    // SAFETY: clearing the update flag is a write-0-to-clear of this interrupt's own flag.
    unsafe { (*TIM1::ptr()).sr().modify(|_, w| w.uif().clear_bit()) };
    cortex_m::interrupt::free(|cs| {
        let mut cell = BOARD.borrow(cs).borrow_mut();
        let Some(b) = cell.as_mut() else { return };
        let fast = SampleTime::Cycles_2_5;
        let iu = b.adc1.convert(&b.current_u, fast);
        let iv = b.adc2.convert(&b.current_v, fast);
        let iw = b.adc2.convert(&b.current_w, fast);
        let vbus = b.adc1.convert(&b.vbus, SampleTime::Cycles_12_5);
        let pot = b.adc1.convert(&b.pot, SampleTime::Cycles_12_5);
        let amps = |adc_volts: f32| (adc_volts - CURRENT_BIAS_V) * AMPS_PER_VOLT;
        let i_abc = Abc::new(
            amps(volts(&b.adc1, iu)),
            amps(volts(&b.adc2, iv)),
            amps(volts(&b.adc2, iw)),
        );
        let vdc = volts(&b.adc1, vbus) * VBUS_PER_VOLT;
        let speed_ref = (volts(&b.adc1, pot) / 3.3 * 2.0 - 1.0) * b.rated_speed;

        let out = b.drive.step(i_abc, vdc, speed_ref);
        let duty = |d: f32| (d * f32::from(b.max_duty)) as u16;
        let (u, v, w) = &mut b.phases;
        if out.gates_enabled {
            let _ = u.set_duty_cycle(duty(out.duty.a));
            let _ = v.set_duty_cycle(duty(out.duty.b));
            let _ = w.set_duty_cycle(duty(out.duty.c));
            u.enable();
            v.enable();
            w.enable();
        } else {
            // Offset calibration, or a trip: every switch off (out.flags says which).
            u.disable();
            v.disable();
            w.disable();
        }
    });
}

#[panic_handler]
fn panic(_: &PanicInfo) -> ! {
    // Reached only from `main` (a refused configuration); the gates are still off then.
    loop {
        cortex_m::asm::bkpt();
    }
}
