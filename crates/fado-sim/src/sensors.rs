//! Measurement chain: phase-current sensing with offset, gain error, white noise and ADC
//! quantisation (docs/method/estimator.md, "The paper's motor and drive" \[A\]), DC-link voltage sensing, and the evaluation encoder.
//! Every non-ideality can be switched off on its own; the noise comes from a seeded
//! xoshiro256++ generator, so a run is reproducible bit for bit for a given seed.

use fado_core::Abc;
use fado_core::machine::PAPER_RATED_CURRENT;
use rand_distr::{Distribution, Normal};
use rand_xoshiro::Xoshiro256PlusPlus;
use rand_xoshiro::rand_core::SeedableRng;
use serde::{Deserialize, Serialize};

use crate::error::{SimConfigError, check};

/// Current-sensor parameter record. Two sensors (phases a and b); phase c is reconstructed as
/// −(a + b), as on most drives.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CurrentSensorParams {
    /// Offset of the phase-a sensor as a fraction of the motor's rated current. Default
    /// 20 mA of the paper's 21.78 A (docs/method/estimator.md, "The paper's motor and drive" \[A\]), 9.2e-4.
    pub offset_a_ratio: f64,
    /// Offset of the phase-b sensor as a fraction of the rated current. Default −10 mA of
    /// the paper's 21.78 A (docs/method/estimator.md, "The paper's motor and drive" \[A\]), −4.6e-4.
    pub offset_b_ratio: f64,
    /// Relative gain error of the phase-a sensor. Default +0.5 % (docs/method/estimator.md, "The paper's motor and drive" \[A\]).
    pub gain_error_a: f64,
    /// Relative gain error of the phase-b sensor. Default 0 (the 0.5 % is the mismatch) \[A\].
    pub gain_error_b: f64,
    /// White noise per sensor, rms, as a fraction of the rated current. Default 10 mA of the
    /// paper's 21.78 A (docs/method/estimator.md, "The paper's motor and drive" \[A\]), 4.6e-4.
    pub noise_rms_ratio: f64,
    /// ADC resolution in bits. Default 12 (docs/method/estimator.md, "The paper's motor and drive" \[A\]).
    pub adc_bits: u32,
    /// ADC full scale as a multiple of the rated current: the range is ±this × rated current.
    /// Default 50 A of the paper's 21.78 A (docs/method/estimator.md, "The paper's motor and drive" \[A\]), 2.296: a sensor sized for the
    /// motor, not one fixed range (50 A would clip a 240 A motor at a fifth of its rating and
    /// give a 6 A one a 4 % LSB).
    pub adc_full_scale_ratio: f64,
    /// Apply the offsets. Default true.
    pub enable_offset: bool,
    /// Apply the gain errors. Default true.
    pub enable_gain_error: bool,
    /// Apply the noise. Default true.
    pub enable_noise: bool,
    /// Apply the ADC quantisation and clipping. Default true.
    pub enable_quantization: bool,
    /// Seed of the noise generator. Default 1.
    pub seed: u64,
}

impl Default for CurrentSensorParams {
    fn default() -> Self {
        Self {
            offset_a_ratio: 0.020 / PAPER_RATED_CURRENT,
            offset_b_ratio: -0.010 / PAPER_RATED_CURRENT,
            gain_error_a: 0.005,
            gain_error_b: 0.0,
            noise_rms_ratio: 0.010 / PAPER_RATED_CURRENT,
            adc_bits: 12,
            adc_full_scale_ratio: 50.0 / PAPER_RATED_CURRENT,
            enable_offset: true,
            enable_gain_error: true,
            enable_noise: true,
            enable_quantization: true,
            seed: 1,
        }
    }
}

impl CurrentSensorParams {
    /// Ideal sensors: every non-ideality switched off.
    pub fn ideal() -> Self {
        Self {
            enable_offset: false,
            enable_gain_error: false,
            enable_noise: false,
            enable_quantization: false,
            ..Self::default()
        }
    }

    /// Checks every field; the error names the key.
    pub fn validate(&self) -> Result<(), SimConfigError> {
        check::finite("offset_a_ratio", self.offset_a_ratio)?;
        check::finite("offset_b_ratio", self.offset_b_ratio)?;
        check::in_range("gain_error_a", self.gain_error_a, -0.5, 0.5)?;
        check::in_range("gain_error_b", self.gain_error_b, -0.5, 0.5)?;
        check::non_negative("noise_rms_ratio", self.noise_rms_ratio)?;
        if !(2..=24).contains(&self.adc_bits) {
            return Err(SimConfigError::new("adc_bits", "must be in 2..=24"));
        }
        check::positive("adc_full_scale_ratio", self.adc_full_scale_ratio)?;
        Ok(())
    }
}

/// The two phase-current sensors and their ADC.
#[derive(Clone, Debug)]
pub struct CurrentSensor {
    params: CurrentSensorParams,
    rng: Xoshiro256PlusPlus,
    noise: Normal<f64>,
    lsb: f64,
    /// The ratios resolved against the rated current (A).
    offset_a: f64,
    offset_b: f64,
    noise_rms: f64,
    full_scale: f64,
}

impl CurrentSensor {
    /// Sensors from a validated record, for a motor of `rated_current` (A peak) that the
    /// record's ratios refer to.
    pub fn new(params: CurrentSensorParams, rated_current: f64) -> Result<Self, SimConfigError> {
        params.validate()?;
        check::positive("rated_current", rated_current)?;
        let noise_rms = params.noise_rms_ratio * rated_current;
        let noise = Normal::new(0.0, noise_rms)
            .map_err(|e| SimConfigError::new("noise_rms_ratio", e.to_string()))?;
        let full_scale = params.adc_full_scale_ratio * rated_current;
        let lsb = 2.0 * full_scale / (1u64 << params.adc_bits) as f64;
        Ok(Self {
            rng: Xoshiro256PlusPlus::seed_from_u64(params.seed),
            offset_a: params.offset_a_ratio * rated_current,
            offset_b: params.offset_b_ratio * rated_current,
            noise_rms,
            full_scale,
            params,
            noise,
            lsb,
        })
    }

    /// Parameters.
    pub fn params(&self) -> &CurrentSensorParams {
        &self.params
    }

    fn channel(&mut self, i: f64, offset: f64, gain_error: f64) -> f64 {
        let p = &self.params;
        let mut x = i;
        if p.enable_gain_error {
            x *= 1.0 + gain_error;
        }
        if p.enable_offset {
            x += offset;
        }
        if p.enable_noise && self.noise_rms > 0.0 {
            x += self.noise.sample(&mut self.rng);
        }
        if p.enable_quantization {
            let fs = self.full_scale;
            x = ((x / self.lsb).round() * self.lsb).clamp(-fs, fs - self.lsb);
        }
        x
    }

    /// Samples the true phase currents; returns (a, b, −a−b) as the drive sees them.
    pub fn measure(&mut self, i_true: Abc<f64>) -> Abc<f64> {
        let (oa, ob, ga, gb) = (
            self.offset_a,
            self.offset_b,
            self.params.gain_error_a,
            self.params.gain_error_b,
        );
        let a = self.channel(i_true.a, oa, ga);
        let b = self.channel(i_true.b, ob, gb);
        Abc::new(a, b, -a - b)
    }
}

/// DC-link voltage sensor parameter record.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DcLinkSensorParams {
    /// Relative gain error. Default 0 \[A\].
    pub gain_error: f64,
}

impl Default for DcLinkSensorParams {
    fn default() -> Self {
        Self { gain_error: 0.0 }
    }
}

impl DcLinkSensorParams {
    /// Checks every field; the error names the key.
    pub fn validate(&self) -> Result<(), SimConfigError> {
        check::in_range("gain_error", self.gain_error, -0.5, 0.5)?;
        Ok(())
    }

    /// The measured DC-link voltage.
    pub fn measure(&self, vdc: f64) -> f64 {
        vdc * (1.0 + self.gain_error)
    }
}

/// Incremental encoder for evaluation and for sensored reference controllers: 5000 ppr
/// (paper §V \[P\]) read in quadrature, i.e. 4·ppr counts per mechanical revolution.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Encoder {
    /// Lines per mechanical revolution.
    pub ppr: u32,
}

impl Default for Encoder {
    fn default() -> Self {
        Self { ppr: 5000 }
    }
}

impl Encoder {
    /// The mechanical angle as the encoder counts it (floor to a count).
    pub fn angle_mech(&self, theta_mech: f64) -> f64 {
        let count = std::f64::consts::TAU / (4.0 * self.ppr as f64);
        (theta_mech / count).floor() * count
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn statistics_of_the_error_match_the_record() {
        // Without the ADC the error is offset + gain error + N(0, σ) exactly.
        let p = CurrentSensorParams {
            enable_quantization: false,
            ..Default::default()
        };
        let mut s = CurrentSensor::new(p, PAPER_RATED_CURRENT).unwrap();
        let n = 200_000;
        let (mut sa, mut sa2, mut sb) = (0.0, 0.0, 0.0);
        for _ in 0..n {
            let m = s.measure(Abc::new(10.0, 0.0, -10.0));
            let ea = m.a - 10.0;
            sa += ea;
            sa2 += ea * ea;
            sb += m.b;
            assert!((m.a + m.b + m.c).abs() < 1e-12);
        }
        let mean_a = sa / n as f64;
        let rms_a = (sa2 / n as f64 - mean_a * mean_a).sqrt();
        assert!(
            (mean_a - 0.07).abs() < 2e-4,
            "offset 0.02 + 0.5 % of 10 A: {mean_a}"
        );
        assert!((rms_a - 0.01).abs() < 2e-4, "{rms_a}");
        assert!((sb / n as f64 + 0.01).abs() < 2e-4);
    }

    #[test]
    fn ideal_is_transparent_and_seed_is_deterministic() {
        let mut s = CurrentSensor::new(CurrentSensorParams::ideal(), PAPER_RATED_CURRENT).unwrap();
        let m = s.measure(Abc::new(1.234_567, -0.5, -0.734_567));
        assert_eq!((m.a, m.b), (1.234_567, -0.5));
        let run = || {
            let mut s =
                CurrentSensor::new(CurrentSensorParams::default(), PAPER_RATED_CURRENT).unwrap();
            (0..10)
                .map(|_| s.measure(Abc::new(0.3, 0.1, -0.4)).a)
                .collect::<Vec<_>>()
        };
        assert_eq!(run(), run());
    }

    #[test]
    fn quantises_to_lsb_and_clips() {
        let p = CurrentSensorParams {
            enable_noise: false,
            enable_offset: false,
            enable_gain_error: false,
            ..Default::default()
        };
        let mut s = CurrentSensor::new(p, PAPER_RATED_CURRENT).unwrap();
        let lsb = 100.0 / 4096.0;
        let m = s.measure(Abc::new(1.0, 80.0, 0.0));
        assert!(((m.a / lsb) - (m.a / lsb).round()).abs() < 1e-9);
        assert!((m.a - 1.0).abs() <= lsb / 2.0);
        assert!(m.b <= 50.0);
        let bad = CurrentSensorParams {
            adc_bits: 0,
            ..Default::default()
        };
        assert_eq!(bad.validate().unwrap_err().key, "adc_bits");
    }
}
