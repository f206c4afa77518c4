#!/usr/bin/env python3
"""Fits the short f32 polynomials of fado-core (observer.rs `f32_gains`, approx.rs `atan2`).

Each polynomial is near-minimax for its stated error (Lawson's iteratively reweighted least
squares on a Chebyshev-spaced grid, in f64), with the coefficients rounded to f32 one at a
time, lowest first, the higher ones refitted after each rounding. Prints the error of the fit
and the error of the rounded polynomial evaluated in f32 (Horner, no fused multiply-add, as
the Rust code does) on a dense grid, then the coefficients as Rust literals (shortest repr that
rounds back to the same f32).

Usage: python3 scripts/fit_approx.py   (numpy only; about 10 s)
"""

import numpy as np


def lawson(t, f, w, n, fixed, iters=400):
    """Coefficients c (degree n−1 in t) minimising max |w·(P − f)|, the first len(fixed)
    coefficients held at `fixed`."""
    v = np.vander(t, n, increasing=True)
    nf = len(fixed)
    r = f - v[:, :nf] @ np.array(fixed, dtype=np.float64)
    vr = v[:, nf:]
    lw = np.full(len(t), 1.0 / len(t))
    for _ in range(iters):
        s = np.sqrt(lw) * w
        c, *_ = np.linalg.lstsq(vr * s[:, None], r * s, rcond=None)
        e = np.abs(w * (vr @ c - r))
        lw = lw * e
        lw /= lw.sum()
    return np.concatenate([np.array(fixed, dtype=np.float64), c]), e.max()


def fit_f32(lo, hi, f, w, n, first=None):
    k = np.arange(4000)
    t = lo + (hi - lo) * (1 - np.cos(np.pi * k / (len(k) - 1))) / 2
    fixed = [] if first is None else [first]
    err = None
    for i in range(len(fixed), n):
        c, err = lawson(t, f(t), w(t), n, fixed)
        fixed.append(float(np.float32(c[i])))
    if err is None:
        _, err = lawson(t, f(t), w(t), n, fixed[:-1])
    return np.array(fixed, dtype=np.float32), err


def horner_f32(c, t):
    t = t.astype(np.float32)
    p = np.full_like(t, c[-1])
    for k in range(len(c) - 2, -1, -1):
        p = c[k] + t * p
    return p


def sinc(t):
    x = np.sqrt(t)
    return np.where(t > 0, np.sin(x) / np.where(t > 0, x, 1), 1.0)


def one_minus_cos_over_x2(t):
    x = np.sqrt(t)
    return np.where(t > 0, 2 * np.sin(x / 2) ** 2 / np.where(t > 0, t, 1), 0.5)


def one_minus_exp_over_y(y):
    return np.where(y > 0, -np.expm1(-y) / np.where(y > 0, y, 1), 1.0)


def half_x_cot_half_x(t):
    h = np.sqrt(t) / 2
    return np.where(t > 0, np.where(t > 0, h, 1) / np.tan(np.where(t > 0, h, 1)), 1.0)


def atan_over_t(s):
    t = np.sqrt(s)
    return np.where(s > 0, np.arctan(t) / np.where(s > 0, t, 1), 1.0)


def report(name, c, fit_err, var_lo, var_hi, f, err_of):
    t = np.linspace(var_lo, var_hi, 400001)
    p = horner_f32(c, t).astype(np.float64)
    e = np.abs(err_of(t, p, f(t))).max()
    lits = ", ".join(repr(float(v)) if False else np.format_float_positional(v, unique=True)
                     for v in c)
    print(f"{name}: {len(c)} coefficients, fit {fit_err:.2e}, evaluated in f32 {e:.2e}")
    print(f"    [{lits}]")


def main():
    rel = lambda t, p, f: p / f - 1  # noqa: E731
    # Observer gains, x = ω·Ts with |x| ≤ 0.5: relative errors. A leading coefficient of 1 or
    # 1/2 (the Taylor value, exact at x = 0) is an FPU immediate, no literal-pool load.
    for name, f, lo, hi, n, first in [
        ("sin(x)/x in x²", sinc, 0.0, 0.25, 3, 1.0),
        ("(1 - cos x)/x² in x²", one_minus_cos_over_x2, 0.0, 0.25, 3, 0.5),
        ("(1 - e^-y)/y in y", one_minus_exp_over_y, 0.0, 0.5, 5, 1.0),
        ("(1 - e^-y)/y in y (4 terms)", one_minus_exp_over_y, 0.0, 0.5, 4, None),
        ("(x/2)·cot(x/2) in x²", half_x_cot_half_x, 0.0, 0.25, 3, 1.0),
    ]:
        c, e = fit_f32(lo, hi, f, lambda t, f=f: 1 / np.abs(f(t)), n, first)
        report(name, c, e, lo, hi, f, rel)
    # atan(t) = t·P(t²) on [0, 1]: absolute error of atan.
    for n in (5, 6, 8):
        c, e = fit_f32(0.0, 1.0, atan_over_t, np.sqrt, n)

        def abs_err(s, p, f):
            return np.sqrt(s) * (p - f)

        report(f"atan(t)/t in t² (degree {2 * n - 1})", c, e, 0.0, 1.0, atan_over_t, abs_err)


if __name__ == "__main__":
    main()
