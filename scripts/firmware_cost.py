#!/usr/bin/env python3
"""Cost of fado's estimator step on a Cortex-M4F, from a QEMU instruction trace.

Used by scripts/firmware-cost.sh (which builds the image and runs QEMU) and by
scripts/check-firmware-symbols.sh (which needs only the call graph). Method and assumptions:
docs/results/firmware-cost.md.

  firmware_cost.py graph ELF ROOT            functions reachable from ROOT, their .text size,
                                             and any forbidden (soft-f64, panic, fmt) symbol;
                                             exit 1 if one is reachable
  firmware_cost.py ranges ELF ROOT[,ROOT...] EXTRA...
                                             QEMU -dfilter ranges of the ROOTs' reachable code
  firmware_cost.py trace ELF ROOT TRACE [TAIL [OTHER_ROOT...]]
                                             per-step instructions and cycle estimate of ROOT
                                             (a step ends at ROOT's next entry, or at the entry
                                             of an OTHER_ROOT traced in the same run; only
                                             instructions of functions reachable from ROOT
                                             count, so that a function another root shares,
                                             called by the image between steps, is not)

Cycle model (Cortex-M4 Technical Reference Manual r0p1, table 3-1 "Cortex-M4 instruction
set summary" and table 7-1 "FPU instruction set"), zero wait states:
  data processing, IT, MOV, CMP, shifts, MUL, UMULL/SMULL/UMLAL/SMLAL  1
  MLA, MLS                                                             2
  SDIV, UDIV                                                           12 (worst case)
  LDR/STR (single)  2, or 1 when it follows another single load/store (pipelined)
  LDRD/STRD  3;  LDM/STM/PUSH/POP  1 + N (+ P with PC in the list)
  B, BL, BX, BLX, CBZ/CBNZ taken: 1 + P with P = 2 (TRM: refill of 1 to 3); not taken: 1
  VADD/VSUB/VMUL/VNMUL/VABS/VNEG/VCMP/VCVT/VMOV/VMRS/VMSR  1 (VMOV of two core registers 2)
  VMLA/VMLS/VNMLA/VNMLS/VFMA/VFMS/VFNMA/VFNMS  3;  VDIV, VSQRT  14
  VLDR/VSTR  2;  VLDM/VSTM/VPUSH/VPOP  1 + N (N single-precision registers)
Not modelled: interrupt entry/exit (12 cycles, + lazy FPU stacking), flash wait states, bus
contention, load-use and FPU register hazards.
"""

import os
import re
import subprocess
import sys
from collections import Counter, defaultdict

OBJDUMP = "arm-none-eabi-objdump"
NM = "arm-none-eabi-nm"
ADDR2LINE = "arm-none-eabi-addr2line"
REFILL = 2

# Software double precision (compiler-builtins / libgcc names) and panic or formatting code.
FORBIDDEN = re.compile(
    r"__aeabi_d|__aeabi_[fil]2d|__aeabi_l2d|__(add|sub|mul|div|neg)df3|__(extendsfdf2|"
    r"truncdfsf2)|__(fix|fixuns)df|__float(un)?[sd]idf|__(eq|ne|lt|le|gt|ge|unord|cmp)df2|"
    r"panic|3fmt|Formatter|unwrap_failed|expect_failed|slice_index|str_index"
)

INSN = re.compile(r"^\s*([0-9a-f]+):\s+([0-9a-f]{4}(?: [0-9a-f]{4})?)\s+(\S+)\s*(.*)$")
FUNC = re.compile(r"^([0-9a-f]{8}) <(.+)>:$")
TARGET = re.compile(r"<([^>+]+)(?:\+0x[0-9a-f]+)?>")


def disassemble(elf):
    """{address: (size, mnemonic, operands, function)}, {function: (start, end)}."""
    text = subprocess.run(
        [OBJDUMP, "-d", elf], check=True, capture_output=True, text=True
    ).stdout
    insns, funcs = {}, {}
    current = None
    for line in text.splitlines():
        m = FUNC.match(line)
        if m:
            current = m.group(2)
            funcs.setdefault(current, [int(m.group(1), 16), int(m.group(1), 16)])
            continue
        m = INSN.match(line)
        if m and current is not None:
            addr = int(m.group(1), 16)
            size = 2 if len(m.group(2)) == 4 else 4
            insns[addr] = (size, m.group(3), m.group(4), current)
            funcs[current][1] = max(funcs[current][1], addr + size)
    return insns, {f: tuple(r) for f, r in funcs.items()}


def call_graph(insns):
    calls = defaultdict(set)
    indirect = defaultdict(set)
    for addr, (_size, mnem, ops, func) in insns.items():
        base = mnem.split(".")[0]
        if base.startswith(("b", "cb")) and base not in ("bic", "bics", "bfi", "bfc"):
            t = TARGET.search(ops)
            if t and t.group(1) != func:
                calls[func].add(t.group(1))
            elif base in ("blx", "bx") and "lr" not in ops and not t:
                indirect[func].add(addr)
        elif mnem.startswith(("pop", "ldm", "ldr")) and "pc" in ops.split(";")[0]:
            if mnem.startswith("ldr"):
                indirect[func].add(addr)
    return calls, indirect


def reachable(calls, root):
    seen, todo = set(), [root]
    while todo:
        f = todo.pop()
        if f in seen:
            continue
        seen.add(f)
        todo.extend(calls.get(f, ()))
    return seen


def symbol_sizes(elf):
    out = subprocess.run(
        [NM, "-S", elf], check=True, capture_output=True, text=True
    ).stdout
    sizes = {}
    for line in out.splitlines():
        parts = line.split()
        if len(parts) == 4 and parts[2] in "tTwW":
            sizes[parts[3]] = int(parts[1], 16)
    return sizes


def graph(elf, root):
    insns, funcs = disassemble(elf)
    calls, indirect = call_graph(insns)
    if root not in funcs:
        sys.exit(f"{root} is not a function of {elf}")
    seen = reachable(calls, root)
    sizes = symbol_sizes(elf)
    total = 0
    bad = []
    print(f"functions reachable from {root}:")
    for f in sorted(seen, key=lambda f: funcs.get(f, (0, 0))[0]):
        start, end = funcs.get(f, (0, 0))
        size = sizes.get(f, end - start)
        total += size
        flag = ""
        if FORBIDDEN.search(f):
            bad.append(f)
            flag = "   <-- FORBIDDEN (soft double precision, panic or formatting)"
        ind = "  (indirect call/jump)" if indirect.get(f) else ""
        print(f"  {size:6d} B  {f}{ind}{flag}")
    print(f".text reachable from {root}: {total} B in {len(seen)} functions")
    if any(indirect.get(f) for f in seen):
        print(
            "note: indirect calls or jumps exist on this path; their targets are not followed"
        )
    return bad


def ranges(elf, roots, extra):
    insns, funcs = disassemble(elf)
    calls, _ = call_graph(insns)
    names = set(extra)
    for root in roots.split(","):
        names |= reachable(calls, root)
    return ",".join(
        f"0x{funcs[f][0]:x}..0x{funcs[f][1] - 1:x}" for f in sorted(names) if f in funcs
    )


def reglist_count(ops):
    m = re.search(r"\{([^}]*)\}", ops)
    if not m:
        return 1
    n = 0
    for part in m.group(1).split(","):
        part = part.strip()
        if "-" in part:
            a, b = part.split("-")
            k = int(b[1:]) - int(a[1:]) + 1
            n += 2 * k if a.startswith("d") else k
        elif part:
            n += 2 if part.startswith("d") else 1
    return n


def cycles(mnem, ops, taken, prev_single_ls):
    """(cycles, is a single load/store) for one executed instruction."""
    base = mnem.split(".")[0]
    if base.startswith("v"):
        core = base[1:]
        if core.startswith(("div", "sqrt")):
            return 14, False
        if core.startswith(("mla", "mls", "nmla", "nmls", "fma", "fms", "fnma", "fnms")):
            return 3, False
        if core.startswith(("ldr", "str")):
            return 2, False
        if core.startswith(("ldm", "stm", "push", "pop")):
            return 1 + reglist_count(ops), False
        if core.startswith("mov") and ops.count(",") == 2:
            return 2, False
        return 1, False
    if base in ("b", "bl", "bx", "blx", "cbz", "cbnz") or (
        base.startswith("b") and len(base) == 3 and base not in ("bic", "bfi", "bfc")
    ):
        return (1 + REFILL if taken else 1), False
    if base.startswith(("pop", "ldm")):
        n = reglist_count(ops)
        return 1 + n + (REFILL if "pc" in ops else 0), False
    if base.startswith(("push", "stm")):
        return 1 + reglist_count(ops), False
    if base.startswith(("ldrd", "strd")):
        return 3, False
    if base.startswith(("ldr", "str")):
        extra = REFILL if base.startswith("ldr") and ops.startswith("pc") else 0
        return (1 if prev_single_ls else 2) + extra, True
    if base.startswith(("sdiv", "udiv")):
        return 12, False
    if base.startswith(("mla", "mls")):
        return 2, False
    return 1, False


def klass(mnem):
    """The instruction class of one mnemonic, for the report's mix of the step."""
    base = mnem.split(".")[0]
    if base.startswith("v"):
        core = base[1:]
        if core.startswith(("div", "sqrt")):
            return "fp div/sqrt"
        if core.startswith(("mla", "mls", "nmla", "nmls", "fma", "fms", "fnma", "fnms")):
            return "fp multiply-add"
        if core.startswith(("add", "sub", "mul", "nmul", "neg", "abs")):
            return "fp arithmetic"
        if core.startswith(("ldr", "str", "ldm", "stm", "push", "pop")):
            return "fp load/store"
        if core.startswith(("cmp", "mrs")):
            return "fp compare"
        if core.startswith("cvt"):
            return "fp convert"
        return "fp move"
    if base.startswith(("ldr", "str", "ldm", "stm", "push", "pop")):
        return "load/store"
    if base in ("b", "bl", "bx", "blx", "cbz", "cbnz") or base.startswith("it") or (
        base.startswith("b") and len(base) == 3 and base not in ("bic", "bfi", "bfc")
    ):
        return "branch/IT"
    return "integer"


def inline_files(elf, addrs, symbol_of, lines=False):
    """{address: innermost fado-core source file (or 'file:line' with `lines`)} via
    addr2line -i."""
    if not addrs:
        return {}
    out = subprocess.run(
        [ADDR2LINE, "-e", elf, "-i", "-f", "-C", "-a"] + [f"0x{a:x}" for a in addrs],
        check=True,
        capture_output=True,
        text=True,
    ).stdout.splitlines()
    result, cur, frames = {}, None, []

    def close():
        if cur is None:
            return
        label = "other"
        # Innermost frame that lies in fado-core, or else in the image's own source (the
        # paper's kernel), frames listed innermost first.
        for func, loc in frames:
            src = next((d for d in ("fado-core/src/", "cortex-m/src/") if d in loc), None)
            if src is not None:
                label = loc.split(src)[1].split(" ")[0]
                if src == "cortex-m/src/":
                    label = "image:" + label
                if not lines:
                    label = label.split(":")[0]
                break
        else:
            label = symbol_of.get(cur, "other")
        result[cur] = label

    i = 0
    while i < len(out):
        line = out[i]
        if line.startswith("0x"):
            close()
            cur, frames = int(line, 16), []
            i += 1
            continue
        func = line
        loc = out[i + 1] if i + 1 < len(out) else ""
        frames.append((func, loc))
        i += 2
    close()
    return result


def trace(elf, root, path, tail, lines=False, others=()):
    insns, funcs = disassemble(elf)
    entry = funcs[root][0]
    other_entries = {funcs[o][0] for o in others if o in funcs}
    # Only ROOT's own call graph counts: the trace filter holds every root's functions, and
    # one another root shares (memcpy, fminf, ...) may also be called by the image's own code
    # between two steps, which is not the step's work.
    calls, _ = call_graph(insns)
    own = reachable(calls, root)
    marker = funcs["scenario_marker"][0] if "scenario_marker" in funcs else None
    scenarios = []  # list of steps (list of pc lists)
    steps = None
    current = None
    with open(path, errors="replace") as f:
        for line in f:
            if not line.startswith("Trace"):
                continue
            lb = line.find("[")
            pc = int(line[lb + 10 : lb + 18], 16)
            if pc == marker:
                if current is not None and steps is not None:
                    steps.append(current)
                current = None
                steps = []
                scenarios.append(steps)
                continue
            if pc == entry or pc in other_entries:
                if current is not None and steps is not None:
                    steps.append(current)
                current = [pc] if pc == entry else None
            elif current is not None and pc in insns and insns[pc][3] in own:
                current.append(pc)
    if current is not None and steps is not None:
        steps.append(current)
    pcs = sorted({pc for s in scenarios for st in s[-tail:] for pc in st})
    files = inline_files(elf, pcs, {pc: insns[pc][3] for pc in pcs if pc in insns}, lines)
    results = []
    for index, steps in enumerate(scenarios):
        if not steps:
            continue  # ROOT did not run in this scenario
        measured = steps[-tail:]
        n_insn, n_cyc = [], []
        by_file = Counter()
        by_file_insn = Counter()
        by_class = Counter()
        for st in measured:
            c_total = 0
            prev_ls = False
            for k, pc in enumerate(st):
                size, mnem, ops, _func = insns.get(pc, (2, "?", "", "?"))
                nxt = st[k + 1] if k + 1 < len(st) else None
                taken = nxt is None or nxt != pc + size
                c, prev_ls = cycles(mnem, ops, taken, prev_ls)
                c_total += c
                label = files.get(pc, "other")
                by_file[label] += c
                by_file_insn[label] += 1
                by_class[klass(mnem)] += c
            n_insn.append(len(st))
            n_cyc.append(c_total)
        k = len(measured)
        results.append(
            {
                "scenario": index,
                "steps": len(steps),
                "measured": k,
                "insn_mean": sum(n_insn) / k,
                "insn_max": max(n_insn),
                "cyc_mean": sum(n_cyc) / k,
                "cyc_max": max(n_cyc),
                "cyc_last": n_cyc[-8:],
                "by_file": {f: c / k for f, c in by_file.items()},
                "by_file_insn": {f: c / k for f, c in by_file_insn.items()},
                "by_class": {f: c / k for f, c in by_class.items()},
            }
        )
    return results


def main():
    cmd = sys.argv[1]
    if cmd == "graph":
        bad = graph(sys.argv[2], sys.argv[3])
        if bad:
            print("FORBIDDEN symbols reachable from " + sys.argv[3] + ":")
            for b in bad:
                print("  " + b)
            sys.exit(1)
        print(f"OK: no soft double-precision, panic or formatting code reachable from {sys.argv[3]}")
    elif cmd == "ranges":
        print(ranges(sys.argv[2], sys.argv[3], sys.argv[4:]))
    elif cmd == "trace":
        tail = int(sys.argv[5]) if len(sys.argv) > 5 else 300
        # FADO_COST_LINES=N: attribute to fado-core source lines and print the N dearest.
        top = int(os.environ.get("FADO_COST_LINES", "0"))
        others = sys.argv[6:]
        for r in trace(sys.argv[2], sys.argv[3], sys.argv[4], tail, top > 0, others):
            print(
                f"scenario {r['scenario']}: {r['measured']} of {r['steps']} steps measured: "
                f"{r['insn_mean']:.0f} instructions (max {r['insn_max']}), "
                f"{r['cyc_mean']:.0f} cycles (max {r['cyc_max']})"
            )
            # The estimator runs its slow laws round-robin, one per sample (docs/results/firmware-cost.md):
            # the last steps show each slot's cost.
            print("    cycles of the last 8 steps: " + " ".join(str(c) for c in r["cyc_last"]))
            mix = sorted(r["by_class"].items(), key=lambda x: -x[1])
            print("    cycles by instruction class: " + ", ".join(f"{k} {c:.0f}" for k, c in mix))
            rows = sorted(r["by_file"].items(), key=lambda x: -x[1])
            for f, c in rows[: top or None]:
                print(f"    {c:7.1f} cycles {r['by_file_insn'][f]:7.1f} insns  {f}")
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main()
