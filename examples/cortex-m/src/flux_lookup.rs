//! A 16 × 16 flux map in flash and its lookups, out of line: the units the cost script
//! measures for a saturating machine's model (`fado_core::magnetics::FluxMap`).
//!
//! The table is the 2.2 kW IPMSM of the estimator's salient scenarios with q self-saturation
//! (secant Lq falling 30 % at 12 A) and cross-saturation of ψd with |i_q|, over ±12 A. It is a
//! `static` built by a `const fn` (rustc evaluates it; it lands in `.rodata`, in flash): what a
//! firmware does with a map measured or computed off line.

use fado_core::Dq;
use fado_core::magnetics::{
    ConstantInductance, FluxLookup, FluxMap, FluxTable, FluxWarmStart, MachineMagnetics,
    MagneticModel, UniformFluxMap, UniformFluxTable,
};

/// Nodes per axis.
pub const N: usize = 16;

const fn abs(x: f32) -> f32 {
    if x < 0.0 { -x } else { x }
}

/// The table (see the module docs).
const fn table() -> FluxTable<f32, N, N> {
    let mut t = FluxTable {
        i_d: [0.0; N],
        i_q: [0.0; N],
        psi_d: [[0.0; N]; N],
        psi_q: [[0.0; N]; N],
    };
    let mut k = 0;
    while k < N {
        let x = -12.0 + 24.0 * k as f32 / (N - 1) as f32;
        t.i_d[k] = x;
        t.i_q[k] = x;
        k += 1;
    }
    let mut k = 0;
    while k < N {
        let mut m = 0;
        while m < N {
            let (id, iq) = (t.i_d[k], t.i_q[m]);
            t.psi_d[k][m] = 0.545 + 0.036 * id - 2e-4 * iq * iq;
            t.psi_q[k][m] = 0.051 * iq / (1.0 + 0.036 * abs(iq));
            m += 1;
        }
        k += 1;
    }
    t
}

/// The table in flash.
pub static TABLE: FluxTable<f32, N, N> = table();

/// The table as a checked map, in flash too (built and checked by the compiler,
/// `FluxTable::const_map`): any rectangular grid's form.
pub static MAP: FluxMap<'static, f32> = TABLE.const_map();

/// The same table for the uniform-grid lookup (`UniformFluxTable`: interleaved nodes, the
/// shape in the type), in flash, built and checked by the compiler.
pub static UNIFORM: UniformFluxTable<f32, N, N> = UniformFluxTable::from_f32_table(&TABLE);

/// [`UNIFORM`] borrowed with its shape at run time, in flash too: what the saturating
/// machine's `MachineModel` borrows (`MachineMagnetics::Uniform`).
pub static UNIFORM_MAP: UniformFluxMap<'static, f32> = UNIFORM.map();

/// ψ(i) from [`UNIFORM`]: the lookup a firmware's own code makes in its interrupt.
#[inline(never)]
#[unsafe(no_mangle)]
pub fn uniform_table_lookup(table: &UniformFluxTable<f32, N, N>, i: Dq<f32>) -> Dq<f32> {
    table.flux(i)
}

/// ψ(i) from a machine record's model as the estimator's step evaluates it
/// (`MachineMagnetics::flux_warm`: by reference, the match on the model and the lookup inlined
/// into the caller; the warm start is the algebraic model's and a map leaves it alone).
#[inline(never)]
#[unsafe(no_mangle)]
pub fn step_map_lookup(model: &MachineMagnetics<f32>, i: Dq<f32>) -> Dq<f32> {
    let linear = ConstantInductance {
        ld: 0.036,
        lq: 0.051,
        flux_linkage: 0.545,
    };
    model.flux_warm(linear, i, i, &FluxWarmStart::empty()).0
}

/// ψ(i) from [`UNIFORM`] named by its type, as the estimator's step compiled for the table
/// evaluates it (`EstimatorState::step_lean_in`, `FluxLookup::flux_warm`): the table's
/// address and grid constants of the code, no match on the model, no index checked.
#[inline(never)]
#[unsafe(no_mangle)]
pub fn step_table_lookup(i: Dq<f32>) -> Dq<f32> {
    let linear = ConstantInductance {
        ld: 0.036,
        lq: 0.051,
        flux_linkage: 0.545,
    };
    FluxLookup::flux_warm(&&UNIFORM, linear, i, i, &FluxWarmStart::empty()).0
}

/// ψ(i): one bilinear lookup (the cell from the uniform axes' inverse spacing, four corners
/// per table, the interpolation) — the unit of the ≤ 60-cycle target.
#[inline(never)]
#[unsafe(no_mangle)]
pub fn flux_map_lookup(map: &FluxMap<'static, f32>, i: Dq<f32>) -> Dq<f32> {
    map.flux(i)
}

/// i(ψ): the inverse by Newton's method from a warm start (a plant's or an observer's last
/// current), each iteration one lookup with its Jacobian and a 2 × 2 solve.
#[inline(never)]
#[unsafe(no_mangle)]
pub fn flux_map_inverse(map: &FluxMap<'static, f32>, psi: Dq<f32>, guess: Dq<f32>) -> Dq<f32> {
    map.current_from(psi, guess)
}

/// Runs `n` lookups (by the map and by the uniform table) and inverses along a current
/// trajectory sweeping the map (a rotating current vector of growing amplitude); returns the
/// worst round-trip error |i(ψ(i)) − i| or difference between the two lookups.
pub fn run(n: usize) -> Option<f32> {
    let map = MAP;
    let mut worst: f32 = 0.0;
    let mut guess = Dq::new(0.0, 0.0);
    for k in 0..n {
        let a = 11.0 * (k as f32 + 1.0) / n as f32;
        // An angle on [−π, π] (the generator's sin and cos are valid there).
        let phase = 0.37 * (k % 17) as f32 - core::f32::consts::PI;
        let (s, c) = (crate::sin(phase), crate::cos(phase));
        let i = Dq::new(a * c, a * s);
        let psi = flux_map_lookup(&map, core::hint::black_box(i));
        let same = uniform_table_lookup(&UNIFORM, core::hint::black_box(i));
        worst = worst.max((same - psi).norm());
        let model = MachineMagnetics::Uniform(&UNIFORM_MAP);
        let in_step = step_map_lookup(core::hint::black_box(&model), core::hint::black_box(i));
        worst = worst.max((in_step - psi).norm());
        let typed = step_table_lookup(core::hint::black_box(i));
        worst = worst.max((typed - psi).norm());
        let back = flux_map_inverse(&map, core::hint::black_box(psi), guess);
        guess = back;
        worst = worst.max((back - i).norm());
    }
    Some(worst)
}
