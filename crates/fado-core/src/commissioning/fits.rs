//! The statistics the identification is read from: block means, least-squares lines, the
//! inertia regression and the back-EMF windows.

use crate::Real;

/// Mean and standard error of a signal from block means (no allocation).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct BlockStats<T> {
    pub(super) block: u32,
    pub(super) k: u32,
    pub(super) acc: T,
    pub(super) n: u32,
    pub(super) sum: T,
    pub(super) sum_sq: T,
}

impl<T: Real> BlockStats<T> {
    pub(super) fn new(block: u32) -> Self {
        Self {
            block: block.max(1),
            k: 0,
            acc: T::zero(),
            n: 0,
            sum: T::zero(),
            sum_sq: T::zero(),
        }
    }
    pub(super) fn push(&mut self, x: T) {
        self.acc += x;
        self.k += 1;
        if self.k == self.block {
            let m = self.acc / T::lit(self.block as f64);
            self.sum += m;
            self.sum_sq += m * m;
            self.n += 1;
            self.k = 0;
            self.acc = T::zero();
        }
    }
    pub(super) fn mean(&self) -> T {
        if self.n == 0 {
            T::zero()
        } else {
            self.sum / T::lit(self.n as f64)
        }
    }
    /// Standard error of the mean.
    pub(super) fn sem(&self) -> T {
        if self.n < 2 {
            return T::lit(f64::INFINITY);
        }
        let n = T::lit(self.n as f64);
        let m = self.sum / n;
        let var = ((self.sum_sq - n * m * m) / (n - T::one())).max(T::zero());
        (var / n).sqrt()
    }
}

/// Least-squares line y = a·x + b, accumulated.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Line<T> {
    pub(super) n: T,
    pub(super) sx: T,
    pub(super) sy: T,
    pub(super) sxx: T,
    pub(super) sxy: T,
    pub(super) syy: T,
}

impl<T: Real> Line<T> {
    pub(super) fn push(&mut self, x: T, y: T) {
        self.n += T::one();
        self.sx += x;
        self.sy += y;
        self.sxx += x * x;
        self.sxy += x * y;
        self.syy += y * y;
    }
    /// (slope, standard error of the slope).
    pub(super) fn slope(&self) -> (T, T) {
        let n = self.n;
        if n < T::lit(3.0) {
            return (T::zero(), T::lit(f64::INFINITY));
        }
        let cxx = self.sxx - self.sx * self.sx / n;
        let cxy = self.sxy - self.sx * self.sy / n;
        let cyy = self.syy - self.sy * self.sy / n;
        if cxx <= T::zero() {
            return (T::zero(), T::lit(f64::INFINITY));
        }
        let a = cxy / cxx;
        let res = (cyy - a * cxy).max(T::zero()) / (n - T::lit(2.0));
        (a, (res / cxx).sqrt())
    }
}

/// Two-parameter least squares a·x1 + b·x2 = y, accumulated.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Ls2<T> {
    pub(super) a11: T,
    pub(super) a12: T,
    pub(super) a22: T,
    pub(super) b1: T,
    pub(super) b2: T,
    pub(super) yy: T,
    pub(super) n: T,
}

impl<T: Real> Ls2<T> {
    /// ((a, b), (σ_a, σ_b)).
    pub(super) fn solve(&self) -> Option<((T, T), (T, T))> {
        let det = self.a11 * self.a22 - self.a12 * self.a12;
        if det.partial_cmp(&T::zero()) != Some(core::cmp::Ordering::Greater) || self.n < T::lit(4.0)
        {
            return None;
        }
        let j = (self.b1 * self.a22 - self.b2 * self.a12) / det;
        let b = (self.a11 * self.b2 - self.a12 * self.b1) / det;
        let res = (self.yy - j * self.b1 - b * self.b2).max(T::zero()) / (self.n - T::lit(2.0));
        Some((
            (j, b),
            ((res * self.a22 / det).sqrt(), (res * self.a11 / det).sqrt()),
        ))
    }
}

/// The inertia regression Δω = a·x1 + b·x2 with x1 = ∫T̂e = λ̂f·u + r split into its
/// magnet part (u = ∫1.5·p·i_q dt) and reluctance part (r = ∫1.5·p·(L̂d − L̂q)·i_d·i_q dt),
/// so that it can be solved with the λ̂f known only at the end (the second back-EMF window
/// lies between the torque steps).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct JFit<T> {
    pub(super) uu: T,
    pub(super) ur: T,
    pub(super) rr: T,
    pub(super) ux: T,
    pub(super) rx: T,
    pub(super) xx: T,
    pub(super) uy: T,
    pub(super) ry: T,
    pub(super) xy: T,
    pub(super) yy: T,
    pub(super) n: T,
}

impl<T: Real> JFit<T> {
    pub(super) fn push(&mut self, u: T, r: T, x2: T, y: T) {
        self.uu += u * u;
        self.ur += u * r;
        self.rr += r * r;
        self.ux += u * x2;
        self.rx += r * x2;
        self.xx += x2 * x2;
        self.uy += u * y;
        self.ry += r * y;
        self.xy += x2 * y;
        self.yy += y * y;
        self.n += T::one();
    }
    /// The normal equations with x1 = λ·u + r.
    pub(super) fn with_flux(&self, flux: T) -> Ls2<T> {
        Ls2 {
            a11: flux * flux * self.uu + T::lit(2.0) * flux * self.ur + self.rr,
            a12: flux * self.ux + self.rx,
            a22: self.xx,
            b1: flux * self.uy + self.ry,
            b2: self.xy,
            yy: self.yy,
            n: self.n,
        }
    }
}

/// The inertia test's data reduction: within each contiguous stretch of collected samples
/// (a segment), the running integrals U(t) = ∫1.5·p·i_q, R(t) = ∫1.5·p·(L̂d − L̂q)·i_d·i_q
/// and W(t) = ∫ω̂_mech from the segment's start, and, per window of `J_WINDOW`, the means
/// of ω̂_mech, U, R and W. Since ω(t) = ω(t₀) + (λf·U + R)/J − (B/J)·W at every instant,
/// the difference of two consecutive windows' means obeys the same equation with ω(t₀)
/// gone; the speed enters as a mean over a window, not as two samples (the PLL's speed
/// ripple at six times the electrical frequency, ±30 r/min on the 50 kW IPMSM preset at a
/// quarter of its rated speed, otherwise lands on Δω sample by sample).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct JWindows<T> {
    pub(super) run_u: T,
    pub(super) run_r: T,
    pub(super) run_w: T,
    pub(super) k: u32,
    pub(super) sum: [T; 4],
    pub(super) prev: Option<[T; 4]>,
}

impl<T: Real> JWindows<T> {
    /// A break in the data: the next sample starts a new segment.
    pub(super) fn reset(&mut self) {
        *self = Self::default();
    }
    /// One sample: the mechanical speed ω̂ (rad/s), the rates 1.5·p·i_q and
    /// 1.5·p·(L̂d − L̂q)·i_d·i_q; a finished window goes into `fit`.
    pub(super) fn push(&mut self, omega: T, u: T, r: T, ts: T, n: u32, fit: &mut JFit<T>) {
        self.run_u += u * ts;
        self.run_r += r * ts;
        self.run_w += omega * ts;
        for (s, x) in self
            .sum
            .iter_mut()
            .zip([omega, self.run_u, self.run_r, self.run_w])
        {
            *s += x;
        }
        self.k += 1;
        if self.k >= n {
            let kk = T::lit(self.k as f64);
            let m = self.sum.map(|x| x / kk);
            if let Some(p) = self.prev {
                // Δω̄ = (λf·ΔŪ + ΔR̄)/J − (B/J)·ΔW̄.
                fit.push(m[1] - p[1], m[2] - p[2], -(m[3] - p[3]), m[0] - p[0]);
            }
            self.prev = Some(m);
            self.sum = [T::zero(); 4];
            self.k = 0;
        }
    }
}

/// One back-EMF window: ∫e_f dt and ∫ω̂ dt (e_f = E_q − ω̂·(L̂d − L̂q)·i_d, the magnet's EMF),
/// the time, and block means of e_f/ω̂ for the scatter.
#[derive(Clone, Copy, Debug)]
pub(super) struct EmfWindow<T> {
    pub(super) e: T,
    pub(super) w: T,
    pub(super) time: T,
    pub(super) blocks: BlockStats<T>,
}

impl<T: Real> EmfWindow<T> {
    pub(super) fn new(block: u32) -> Self {
        Self {
            e: T::zero(),
            w: T::zero(),
            time: T::zero(),
            blocks: BlockStats::new(block),
        }
    }
    pub(super) fn push(&mut self, e_f: T, w: T, ts: T) {
        self.e += e_f * ts;
        self.w += w * ts;
        self.time += ts;
        self.blocks.push(e_f / w);
    }
    /// Mean speed ω̄, rad/s.
    pub(super) fn speed(&self) -> T {
        self.w / self.time
    }
    /// Mean EMF ē_f, V.
    pub(super) fn emf(&self) -> T {
        self.e / self.time
    }
    /// Standard error of ē_f, V (from the block means of e_f/ω̂ at the mean speed).
    pub(super) fn emf_sem(&self) -> T {
        self.blocks.sem() * self.speed()
    }
}

/// The line ē_f = λf·ω̄ + e₀ through two back-EMF windows: (λf, its relative 1-σ, the
/// windows' speed difference).
pub(super) fn emf_line<T: Real>(w1: &EmfWindow<T>, w2: &EmfWindow<T>) -> (T, T, T) {
    let ds = w2.speed() - w1.speed();
    let flux = (w2.emf() - w1.emf()) / ds;
    let se = (w1.emf_sem() * w1.emf_sem() + w2.emf_sem() * w2.emf_sem()).sqrt();
    (flux, se / ds.abs() / flux.abs(), ds)
}
