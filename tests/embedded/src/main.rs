//! A freestanding firmware image around the fado estimator: no standard library, no C runtime,
//! no allocator, no unwinding. It proves that `fado-core` links into such an image and shows
//! what the estimator costs in code size. The loop stands in for the 10 kHz ISR: the inputs go
//! through `black_box`, as if read from ADC registers, and so does the estimate.
//!
//! On x86-64 Linux the image also runs: `fado-embedded-check N` performs N estimator steps and
//! exits with status 0 (without N it loops forever, like firmware). That lets
//! `scripts/callgrind.sh` count the instructions of the firmware build itself (`libm` maths,
//! LTO), not only of the host build.

#![no_std]
#![no_main]

use core::hint::black_box;
use core::panic::PanicInfo;

use fado_core::{Ab, Estimate, EstimatorConfig, MachineModel, Rotation, SensorlessEstimator};

/// Nothing to unwind to: a panic (there is none on the estimator's path) exits with status 101.
#[panic_handler]
fn panic(_: &PanicInfo) -> ! {
    exit(101)
}

/// `core` is prebuilt with unwinding tables that name this symbol; with `panic = "abort"` it is
/// never called.
#[unsafe(no_mangle)]
pub extern "C" fn rust_eh_personality() {}

/// `memcpy`, which compiled code calls for large moves on every target (on a Cortex-M the
/// `compiler_builtins` of the target provide it). Without Linux's C library this image brings
/// its own: `rep movsb`.
///
/// # Safety
/// As C's `memcpy`: `dest` and `src` valid for `n` bytes and not overlapping.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn memcpy(dest: *mut u8, src: *const u8, n: usize) -> *mut u8 {
    // SAFETY: the caller's contract; `rep movsb` copies rcx bytes from rsi to rdi upwards.
    unsafe {
        core::arch::asm!(
            "rep movsb",
            inout("rcx") n => _,
            inout("rdi") dest => _,
            inout("rsi") src => _,
            options(nostack, preserves_flags)
        );
    }
    dest
}

/// `memset`, as [`memcpy`]: `rep stosb`.
///
/// # Safety
/// As C's `memset`: `dest` valid for `n` bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn memset(dest: *mut u8, c: i32, n: usize) -> *mut u8 {
    // SAFETY: the caller's contract; `rep stosb` stores al into rcx bytes from rdi upwards.
    unsafe {
        core::arch::asm!(
            "rep stosb",
            inout("rcx") n => _,
            inout("rdi") dest => _,
            in("al") c as u8,
            options(nostack, preserves_flags)
        );
    }
    dest
}

/// Entry point, the linker's default entry symbol (there is no C runtime to call `main`).
///
/// The kernel enters it with the stack pointer at `argc` and 16-byte aligned, whereas compiled
/// code expects the alignment of a call (8 bytes off). So it is naked: it hands the initial stack
/// pointer to [`firmware`] and calls it on a correctly aligned stack.
#[unsafe(naked)]
#[unsafe(no_mangle)]
pub extern "C" fn _start() -> ! {
    core::arch::naked_asm!(
        "xor ebp, ebp",
        "mov rdi, rsp",
        "and rsp, -16",
        "call {firmware}",
        "ud2",
        firmware = sym firmware,
    )
}

/// The "firmware": set-up, then the ISR body in a loop.
extern "C" fn firmware(initial_stack: *const usize) -> ! {
    let steps = steps_from_args(initial_stack);
    let Ok(mut estimator) =
        SensorlessEstimator::<f32>::new(EstimatorConfig::for_machine(&MachineModel::paper()))
    else {
        panic!("default configuration is valid");
    };
    // A 20 Hz rotating flux (λf = 0.088 Wb) with 10 A on q, sampled at 10 kHz: the voltage
    // leads the flux by 90°.
    let rotation = Rotation::from_angle(core::f32::consts::TAU * 20.0 * 100e-6).unit();
    let mut unit = Ab::new(1.0_f32, 0.0);
    let mut done: u64 = 0;
    while steps.is_none_or(|n| done < n) {
        let v = unit.mul_j() * (0.088 * core::f32::consts::TAU * 20.0);
        let i = unit.mul_j() * 10.0;
        black_box(isr(&mut estimator, black_box(v), black_box(i)));
        unit = unit.complex_mul(rotation);
        done += 1;
    }
    exit(0)
}

/// The 10 kHz interrupt's estimator work: one call, kept out of line like a real ISR (and so
/// that callgrind can count exactly what is inside).
#[inline(never)]
fn isr(estimator: &mut SensorlessEstimator<f32>, v: Ab<f32>, i: Ab<f32>) -> Estimate<f32> {
    estimator.step(v, i)
}

/// `argv[1]` as a decimal step count, if present and valid.
fn steps_from_args(initial_stack: *const usize) -> Option<u64> {
    // SAFETY: the System V ABI lays out argc, then argc pointers to NUL-terminated strings, at
    // the initial stack pointer; we read within that layout only.
    unsafe {
        if *initial_stack < 2 {
            return None;
        }
        let mut p = *initial_stack.add(2) as *const u8;
        let mut n: u64 = 0;
        while *p != 0 {
            let digit = (*p).wrapping_sub(b'0');
            if digit > 9 {
                return None;
            }
            n = n.checked_mul(10)?.checked_add(u64::from(digit))?;
            p = p.add(1);
        }
        Some(n)
    }
}

/// Linux `exit_group`.
fn exit(status: i32) -> ! {
    // SAFETY: the syscall takes one integer argument and does not return.
    unsafe {
        core::arch::asm!("syscall", in("rax") 231, in("rdi") status, options(noreturn, nostack));
    }
}
