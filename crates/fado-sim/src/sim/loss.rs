//! Loss-of-lock evaluation: excursions of |θ − θ̂|, their onset and the flag's delay.

/// Angle-error thresholds and deadline of the loss-of-lock evaluation (docs/method/lock.md):
/// an excursion starts when |θ − θ̂| leaves 0.25 rad (the clean-run level), the loss's onset is
/// its first crossing of 0.5 rad, it is a loss if it then exceeds 1 rad, and the flag must be
/// up 20 ms after the onset. An excursion ends when the error has stayed below 0.25 rad for
/// [`LOSS_SETTLE_TIME`].
pub(super) const LOSS_START: f64 = 0.5;
pub(super) const LOSS_LOST: f64 = 1.0;
pub(super) const LOSS_SETTLED: f64 = 0.25;
pub(super) const LOSS_DEADLINE: f64 = 0.020;
/// How long |θ − θ̂| must stay below [`LOSS_SETTLED`] for an excursion to end, s: 0.1 s (the
/// detector's default healing time). An estimate that slips poles makes the *wrapped* error
/// pass through zero once per slip cycle; that is no return to lock. Below 0.25 rad for
/// 0.1 s at a time means a slip slower than 0.5 rad / 0.1 s = 5 rad/s electrical (12 r/min
/// mechanical on the paper's 4 pole pairs), i.e. the estimate following the rotor. (Without
/// the dwell, 8 fixed-R̂s losses of the fig11 envelope ended their excursion in a wrap before
/// the deadline and counted as "not raised" with the flag up throughout; docs/method/lock.md.)
pub(super) const LOSS_SETTLE_TIME: f64 = 0.1;

/// An excursion of |θ − θ̂| above [`LOSS_SETTLED`] that reached [`LOSS_START`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct Excursion {
    /// First time above 0.5 rad in the excursion.
    pub(super) onset: f64,
    /// Last time below 0.25 rad before it (−∞: never, e.g. a start-up error).
    pub(super) settled: f64,
    /// At onset + 20 ms: Some(Some(rise)) if the flag was up then, having last risen at
    /// `rise`; Some(None) if it was down; None before the deadline.
    pub(super) up_at_deadline: Option<Option<f64>>,
    /// First rise of the flag at or after the onset, while the excursion lasts.
    pub(super) first_rise: Option<f64>,
}

/// Streaming labels of [`Metrics`]' loss-of-lock fields: flag edges against the angle error.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct LossTracker {
    flag: bool,
    last_rise: Option<f64>,
    /// Last time below 0.25 rad.
    settled: f64,
    /// Since when the error has been below 0.25 rad (NaN: above it now).
    below_since: f64,
    /// The open excursion that reached 0.5 rad, if any.
    current: Option<Excursion>,
    /// The excursion that first exceeded 1 rad; `open` until the error has been below
    /// 0.25 rad for [`LOSS_SETTLE_TIME`] again.
    pub(super) loss: Option<Excursion>,
    open: bool,
}

impl Default for LossTracker {
    fn default() -> Self {
        Self {
            flag: false,
            last_rise: None,
            settled: f64::NEG_INFINITY,
            below_since: f64::NAN,
            current: None,
            loss: None,
            open: false,
        }
    }
}

impl LossTracker {
    /// One sample: time, |θ − θ̂| (None while the gates are off), the flag.
    pub(super) fn observe(&mut self, t: f64, error: Option<f64>, flag: bool) {
        let rise = flag && !self.flag;
        if rise {
            self.last_rise = Some(t);
        }
        self.flag = flag;
        if let Some(e) = error {
            if e < LOSS_SETTLED {
                self.settled = t;
                if self.below_since.is_nan() {
                    self.below_since = t;
                }
                if t - self.below_since >= LOSS_SETTLE_TIME {
                    self.current = None;
                    self.open = false;
                }
            } else {
                self.below_since = f64::NAN;
            }
            if e > LOSS_START {
                self.current.get_or_insert(Excursion {
                    onset: t,
                    settled: self.settled,
                    up_at_deadline: None,
                    first_rise: None,
                });
            }
            if e > LOSS_LOST && self.loss.is_none() {
                self.loss = self.current;
                self.open = true;
            }
        }
        let open = self.open;
        let current = self.current.as_mut();
        let loss = self.loss.as_mut().filter(|_| open);
        for x in [current, loss].into_iter().flatten() {
            if rise && x.first_rise.is_none() {
                x.first_rise = Some(t);
            }
            if x.up_at_deadline.is_none() && t >= x.onset + LOSS_DEADLINE {
                x.up_at_deadline = Some(self.last_rise.filter(|_| flag));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Feeds (time, |θ − θ̂|, flag) at 1 ms steps to a tracker.
    fn track(samples: &[(f64, f64, bool)]) -> LossTracker {
        let mut l = LossTracker::default();
        for &(t, e, flag) in samples {
            l.observe(t, Some(e), flag);
        }
        l
    }

    /// A piecewise-linear error and a flag window, sampled every ms from 0 to `end`.
    fn run(error: &dyn Fn(f64) -> f64, flag: (f64, f64), end: f64) -> LossTracker {
        let n = (end * 1000.0).round() as usize;
        let s: Vec<_> = (0..=n)
            .map(|k| {
                let t = k as f64 * 1e-3;
                (t, error(t), t >= flag.0 && t < flag.1)
            })
            .collect();
        track(&s)
    }

    #[test]
    fn loss_labels_follow_the_definition() {
        // Error ramps 0 → 2 rad between 1 s and 2 s: onset (0.5 rad) at 1.25 s, last below
        // 0.25 rad at 1.124 s.
        let ramp = |t: f64| ((t - 1.0) * 2.0).clamp(0.0, 2.0);
        // Flag up from 1.2 s on: rose 50 ms before the onset, up at the deadline.
        let l = run(&ramp, (1.2, 9.0), 3.0);
        let x = l.loss.unwrap();
        assert!((x.onset - 1.251).abs() < 1e-9, "{x:?}");
        assert!((x.settled - 1.124).abs() < 1e-9, "{x:?}");
        assert_eq!(x.up_at_deadline, Some(Some(1.2)));
        assert_eq!(x.first_rise, None); // no rise after the onset
        // Flag rising 30 ms after the onset: down at the deadline, a late rise.
        let x = run(&ramp, (1.281, 9.0), 3.0).loss.unwrap();
        assert_eq!(x.up_at_deadline, Some(None));
        assert_eq!(x.first_rise, Some(1.281));
        // A flag that rose at start-up and stayed up: up at the deadline, risen at 0.1 s
        // (the evaluation's window then refuses it).
        let x = run(&ramp, (0.1, 9.0), 3.0).loss.unwrap();
        assert_eq!(x.up_at_deadline, Some(Some(0.1)));
        // A start-up excursion beyond 0.5 rad that came back below 0.25 rad does not move the
        // onset of the later loss.
        let bump = |t: f64| {
            if (0.3..0.4).contains(&t) {
                0.6
            } else {
                ramp(t)
            }
        };
        let x = run(&bump, (0.3, 0.35), 3.0).loss.unwrap();
        assert!((x.onset - 1.251).abs() < 1e-9, "{x:?}");
        assert_eq!(x.up_at_deadline, Some(None));
        // Never beyond 1 rad: no loss.
        assert!(run(&|_| 0.7, (0.0, 9.0), 1.0).loss.is_none());
        // An estimate slipping poles (the error growing at 300 rad/s from 1.2 s on, its
        // wrapped value through zero every 21 ms, first at 1.220 s, before the deadline): one
        // excursion, not ended by the wrapped error passing below 0.25 rad for 2 ms at a
        // time; the flag up since 1.0 s is up at its deadline. Only 0.1 s below 0.25 rad ends
        // it.
        let slip = |t: f64| {
            if t < 1.2 {
                0.0
            } else {
                fado_core::wrap_angle(0.3 + 300.0 * (t - 1.2)).abs()
            }
        };
        let x = run(&slip, (1.0, 9.0), 3.0).loss.unwrap();
        assert!((x.onset - 1.201).abs() < 1e-9, "{x:?}");
        assert_eq!(x.up_at_deadline, Some(Some(1.0)));
        let settles = |t: f64| {
            if (1.5..1.7).contains(&t) {
                0.1
            } else {
                slip(t)
            }
        };
        let l = run(&settles, (1.0, 1.25), 3.0);
        assert!(!l.open, "{l:?}"); // settled at 1.6 s: the loss is over
        assert_eq!(l.loss.unwrap().first_rise, None);
    }
}
