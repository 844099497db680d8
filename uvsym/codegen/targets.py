"""Target builds of a C package: Cortex-M4F, Cortex-M7 (bare metal, run under qemu) or the host.

``TARGETS`` names each target's compiler flags (``-mcpu``/``-mfpu``/``-mfloat-abi``, always
``-ffunction-sections -fdata-sections``), the qemu board that runs it (``mps2-an386``: Cortex-M4,
``mps2-an500``: Cortex-M7) and the clock its time figures are quoted at. :func:`target_files`
gives what a package built for a target holds besides its sources, under ``target/``::

    board.h, board.c   startup (vector table, .data/.bss, FPU on), semihosting output and exit,
                       the CMSDK timer the instruction count reads, stack painting (host: stdio)
    link.ld            the memory map of the qemu board (bare metal only)
    harness.c          the package's test vectors (:func:`target_vectors`) run through every
                       function; per call it prints the return code, timer ticks, the stack
                       high-water and each output's bits in hexadecimal (exact)
    toolchain.cmake    a CMake toolchain file with the same compiler and flags
    harness.out        what the harness printed when uvsym built and ran it (written by
                       :meth:`~uvsym.codegen.observer_sets.ObserverSet.write`): ``make run-target``
                       prints the same, to the instruction, on the same toolchain

Nothing is allocated: the harness, like the package, uses static storage only, and prints
through semihosting (``SYS_WRITE0``), not libc I/O.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from uvsym.codegen.example import Example
from uvsym.errors import CodegenError

__all__ = ["TARGETS", "Target", "target", "target_files", "target_vectors"]

VECTORS = 4  # test vectors per function: rows of the example spread over it, else seeded random inputs
CALIBRATION_LOOPS = 100000  # iterations of the two-instruction loop that calibrates timer ticks per instruction


@dataclass(frozen=True)
class Target:
    """name; compiler prefix (``arm-none-eabi-``, ``""`` for the host's cc); flags; qemu machine (None: host);
    clock_mhz: the clock the time figures are quoted at (None: host)."""

    name: str
    prefix: str
    flags: tuple[str, ...]
    machine: str | None
    clock_mhz: float | None
    description: str

    @property
    def bare_metal(self) -> bool:
        return self.machine is not None


_SECTIONS = ("-ffunction-sections", "-fdata-sections")
TARGETS = {t.name: t for t in (
    Target("cortex-m4f", "arm-none-eabi-", ("-mcpu=cortex-m4", "-mthumb", "-mfpu=fpv4-sp-d16", "-mfloat-abi=hard",
                                            *_SECTIONS), "mps2-an386", 168.0,
           "Cortex-M4F (single-precision FPU; double is soft-float), qemu mps2-an386, quoted at 168 MHz"),
    Target("cortex-m7", "arm-none-eabi-", ("-mcpu=cortex-m7", "-mthumb", "-mfpu=fpv5-d16", "-mfloat-abi=hard",
                                           *_SECTIONS), "mps2-an500", 600.0,
           "Cortex-M7 (double-precision FPU), qemu mps2-an500, quoted at 600 MHz"),
    Target("host", "", _SECTIONS, None, None, "the build machine's C compiler (cc), run natively"),
)}


def target(name: str) -> Target:
    """The target called ``name``; CodegenError naming the known ones otherwise."""
    if name not in TARGETS:
        raise CodegenError(f"unknown target {name!r}; known: {', '.join(TARGETS)}")
    return TARGETS[name]


def target_vectors(functions, example: Example | None, seed: int = 0) -> tuple[Example, ...]:
    """One :class:`Example` of ``VECTORS`` rows per exported function: the example's rows spread
    evenly over it for its function, seeded standard-normal inputs (positive last input: a step
    or gain) for the others."""
    rng, vectors = np.random.default_rng(seed), []
    for e in functions:
        f = e.function
        if example is not None and example.function == f.name():
            rows = np.unique(np.linspace(0, example.samples - 1, VECTORS).astype(int))
            vectors.append(Example(f.name(), tuple(a[rows] for a in example.inputs), example.source))
            continue
        inputs = [rng.normal(size=(VECTORS, f.nnz_in(i))) for i in range(f.n_in())]
        if inputs:
            inputs[-1] = np.abs(inputs[-1]) + 0.01
        vectors.append(Example(f.name(), tuple(inputs), f"seeded random inputs (seed {seed})"))
    return tuple(vectors)


_BOARD_H = """/* Board support for the harness: output, exit, timer ticks, stack painting. */
#ifndef UVSYM_BOARD_H
#define UVSYM_BOARD_H
#include <stdint.h>
void board_write(const char* s);
void board_exit(int code);
void board_timer_start(void);
uint32_t board_ticks(void);
uintptr_t board_paint(void);                 /* paints the free stack; returns the stack pointer */
uint32_t board_stack_used(uintptr_t top);    /* bytes used below top since board_paint */
#endif
"""

_BOARD_ARM = """/* Bare-metal board support ({machine} under qemu): vector table, reset (copies .data, clears .bss,
   turns the FPU on), semihosting output and exit, the CMSDK APB timer 0, stack painting. */
#include <stdint.h>
#include "board.h"

extern uint32_t __data_load, __data_start, __data_end, __bss_start, __bss_end, __stack_limit, __stack_top;
int main(void);
void board_reset(void);
static void board_fault(void) {{ board_exit(2); }}

__attribute__((section(".vectors"), used)) static const uintptr_t board_vectors[16] = {{
  (uintptr_t)&__stack_top, (uintptr_t)board_reset, (uintptr_t)board_fault, (uintptr_t)board_fault,
  (uintptr_t)board_fault, (uintptr_t)board_fault, (uintptr_t)board_fault, 0, 0, 0, 0,
  (uintptr_t)board_fault, (uintptr_t)board_fault, 0, (uintptr_t)board_fault, (uintptr_t)board_fault}};

void board_reset(void) {{
  volatile uint32_t* src = &__data_load;
  volatile uint32_t* dst = &__data_start;
  while (dst < &__data_end) *dst++ = *src++;
  for (dst = &__bss_start; dst < &__bss_end;) *dst++ = 0;
#if defined(__ARM_FP)
  *(volatile uint32_t*)0xE000ED88u |= 0xFu << 20; /* CPACR: CP10 and CP11 full access */
  __asm volatile("dsb\\n isb" ::: "memory");
#endif
  board_exit(main());
}}

static int board_semihost(int op, const void* arg) {{
  register int r0 __asm("r0") = op;
  register const void* r1 __asm("r1") = arg;
  __asm volatile("bkpt 0xab" : "+r"(r0) : "r"(r1) : "memory");
  return r0;
}}

void board_write(const char* s) {{ (void)board_semihost(0x04, s); }}

void board_exit(int code) {{
  /* SYS_EXIT: ADP_Stopped_ApplicationExit (qemu exits 0), else RunTimeErrorUnknown (qemu exits 1) */
  (void)board_semihost(0x18, (const void*)(uintptr_t)(code == 0 ? 0x20026u : 0x20023u));
  for (;;) {{
  }}
}}

#define BOARD_TIMER ((volatile uint32_t*)0x40000000u)
void board_timer_start(void) {{
  BOARD_TIMER[2] = 0xFFFFFFFFu; /* RELOAD */
  BOARD_TIMER[1] = 0xFFFFFFFFu; /* VALUE */
  BOARD_TIMER[0] = 1u;          /* CTRL: enable */
}}
uint32_t board_ticks(void) {{ return 0xFFFFFFFFu - BOARD_TIMER[1]; }}

#define BOARD_PAINT 0xA5C3A5C3u
uintptr_t board_paint(void) {{
  volatile uint32_t* p = &__stack_limit;
  uint32_t* sp;
  __asm volatile("mov %0, sp" : "=r"(sp));
  while (p < sp - 16) *p++ = BOARD_PAINT;
  return (uintptr_t)sp;
}}
uint32_t board_stack_used(uintptr_t top) {{
  const volatile uint32_t* p = &__stack_limit;
  while ((uintptr_t)p < top && *p == BOARD_PAINT) ++p;
  return (uint32_t)(top - (uintptr_t)p);
}}
"""

_BOARD_HOST = """/* Host board support: output on stdout, exit; no timer and no stack painting (figures 0). */
#include <stdio.h>
#include <stdlib.h>
#include "board.h"

void board_write(const char* s) { fputs(s, stdout); }
void board_exit(int code) { exit(code); }
void board_timer_start(void) {}
uint32_t board_ticks(void) { return 0u; }
uintptr_t board_paint(void) { return 0u; }
uint32_t board_stack_used(uintptr_t top) { (void)top; return 0u; }
"""

# the qemu MPS2 boards (AN386, AN500) both have 4 MB of SSRAM at 0: code below 2 MB, data and stack above
_LINK = """/* Memory map of qemu's {machine}: 4 MB of SSRAM at 0 (code and constants, then data, bss, stack). */
ENTRY(board_reset)
MEMORY
{{
  FLASH (rx) : ORIGIN = 0x00000000, LENGTH = 2M
  RAM (rwx)  : ORIGIN = 0x00200000, LENGTH = 2M
}}
SECTIONS
{{
  .text : {{ KEEP(*(.vectors)) *(.text*) *(.rodata*) . = ALIGN(4); }} > FLASH
  .ARM.exidx : {{ *(.ARM.exidx*) }} > FLASH
  .data : {{ __data_start = .; *(.data*) . = ALIGN(4); __data_end = .; }} > RAM AT > FLASH
  __data_load = LOADADDR(.data);
  .bss (NOLOAD) : {{ __bss_start = .; *(.bss*) *(COMMON) . = ALIGN(4); __bss_end = .; }} > RAM
  end = __bss_end;
  __stack_top = ORIGIN(RAM) + LENGTH(RAM);
  __stack_limit = __stack_top - 256K;
}}
"""

_TOOLCHAIN = """# CMake toolchain file for {description}:
#   cmake -S . -B build-{name} -DCMAKE_TOOLCHAIN_FILE=target/toolchain.cmake
{system}set(CMAKE_C_COMPILER {cc})
set(CMAKE_C_FLAGS_INIT "{flags}")
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)
"""


def _harness(functions, name: str, precision: str, vectors) -> str:
    """Source of target/harness.c (module docstring)."""
    real, bits = f"{name}_real", "uint64_t" if precision == "double" else "uint32_t"
    digits = 16 if precision == "double" else 8
    parts = []
    for k, (e, v) in enumerate(zip(functions, vectors)):
        f = e.function
        width = sum(f.nnz_in(i) for i in range(f.n_in()))
        rows = ",\n  ".join("{" + ", ".join(repr(float(x)) for x in np.concatenate([a[r] for a in v.inputs])) +
                            ("}" if width else "0}") for r in range(v.samples))
        declare = "".join(f"  static {real} in{i}[{max(1, f.nnz_in(i))}];\n" for i in range(f.n_in()))
        declare += "".join(f"  static {real} out{i}[{max(1, f.nnz_out(i))}];\n" for i in range(f.n_out()))
        offset, fill = 0, []
        for i in range(f.n_in()):
            fill.append(f"    for (i = 0; i < {f.nnz_in(i)}; ++i) in{i}[i] = ({real})v{k}[r][{offset} + i];")
            offset += f.nnz_in(i)
        call = ", ".join([f"in{i}" for i in range(f.n_in())] + [f"out{i}" for i in range(f.n_out())])
        prints = "\n".join(f"    for (i = 0; i < {f.nnz_out(i)}; ++i) put_real(out{i}[i]);" for i in range(f.n_out()))
        parts.append(f"""static const double v{k}[{v.samples}][{max(1, width)}] = {{
  {rows}}};

static void run{k}(void) {{
{declare}  int r, i, rc;
  uint32_t t0, t1, stack;
  uintptr_t top;
  for (r = 0; r < {v.samples}; ++r) {{
{chr(10).join(fill)}
    top = board_paint();
    t0 = board_ticks();
    rc = {name}_{f.name()}({call});
    t1 = board_ticks();
    stack = board_stack_used(top);
    board_write("r {k} ");
    put_u32((uint32_t)r);
    put_u32((uint32_t)rc);
    put_u32(t1 - t0);
    put_u32(stack);
{prints}
    board_write("\\n");
  }}
}}
""")
    runs = "\n".join(f"  run{k}();" for k in range(len(functions)))
    return f"""/* Target harness: every function of {name} on its test vectors. Prints "cal EMPTY LOOP INSTRUCTIONS"
   (timer ticks of nothing and of a loop of known instruction count), then per call
   "r FUNCTION ROW CODE TICKS STACK OUTPUTS...", each output as its {precision}'s bits in hexadecimal, then "end". */
#include <stdint.h>
#include <string.h>
#include "board.h"
#include "{name}.h"

static void put_u32(uint32_t v) {{
  char s[12];
  int i = 10;
  s[11] = '\\0';
  s[10] = ' ';
  do {{
    s[--i] = (char)('0' + v % 10u);
    v /= 10u;
  }} while (v && i > 0);
  board_write(s + i);
}}

static void put_real({real} x) {{
  static const char hex[] = "0123456789abcdef";
  char s[{digits + 2}];
  {bits} b;
  int i;
  memcpy(&b, &x, sizeof b);
  for (i = {digits - 1}; i >= 0; --i) {{
    s[i] = hex[b & 0xFu];
    b >>= 4;
  }}
  s[{digits}] = ' ';
  s[{digits + 1}] = '\\0';
  board_write(s);
}}

static void calibrate(void) {{
  uint32_t t0, t1, t2, t3, n = {CALIBRATION_LOOPS}u;
  t0 = board_ticks();
  t1 = board_ticks();
  t2 = board_ticks();
#if defined(__arm__)
  __asm volatile("1: subs %0, %0, #1\\n bne 1b" : "+r"(n) : : "cc");
#else
  n = 0u;
#endif
  t3 = board_ticks();
  board_write("cal ");
  put_u32(t1 - t0);
  put_u32(t3 - t2 + n);
  put_u32(2u * {CALIBRATION_LOOPS}u);
  board_write("\\n");
}}

{chr(10).join(parts)}
int main(void) {{
  board_timer_start();
  calibrate();
{runs}
  board_write("end\\n");
  return 0;
}}
"""


def target_files(functions, name: str, precision: str, chosen: Target, vectors) -> dict[str, str]:
    """The files of ``target/`` (module docstring) for the package ``name`` built for ``chosen``."""
    cc = f"{chosen.prefix}gcc" if chosen.bare_metal else "cc"
    system = "set(CMAKE_SYSTEM_NAME Generic)\nset(CMAKE_SYSTEM_PROCESSOR arm)\n" if chosen.bare_metal else ""
    files = {"target/board.h": _BOARD_H,
             "target/board.c": _BOARD_ARM.format(machine=chosen.machine) if chosen.bare_metal else _BOARD_HOST,
             "target/harness.c": _harness(functions, name, precision, vectors),
             "target/toolchain.cmake": _TOOLCHAIN.format(description=chosen.description, name=chosen.name,
                                                         system=system, cc=cc, flags=" ".join(chosen.flags))}
    if chosen.bare_metal:
        files["target/link.ld"] = _LINK.format(machine=chosen.machine)
    return files


LINK_FLAGS = ("-nostartfiles", "-Ttarget/link.ld", "-Wl,--gc-sections")
LIBRARIES = ("-lm", "-lc", "-lgcc")
QEMU_FLAGS = ("-nographic", "-monitor", "none", "-serial", "none", "-semihosting-config", "enable=on,target=native",
              "-icount", "shift=10,align=off,sleep=off")  # deterministic: time advances with instructions only


def target_cflags(chosen: Target) -> tuple[str, ...]:
    """C flags of a target build: C99, -O2, the warnings, the target's own flags."""
    from uvsym.codegen.build_files import WARNINGS

    return ("-std=c99", "-O2", *WARNINGS, *chosen.flags)


def qemu_command(chosen: Target, elf: str) -> list[str]:
    """The command that runs the harness image ``elf`` on the target's qemu board."""
    return ["qemu-system-arm", "-machine", chosen.machine, *QEMU_FLAGS, "-kernel", elf]


def target_make_rules(name: str, chosen: Target) -> str:
    """The Makefile's ``target`` (builds target/harness.elf) and ``run-target`` (runs it) rules."""
    cc = f"{chosen.prefix}gcc" if chosen.bare_metal else "$(CC)"
    link = " ".join(LINK_FLAGS) if chosen.bare_metal else ""
    run = " ".join(qemu_command(chosen, "target/harness.elf")) if chosen.bare_metal else "./target/harness.elf"
    return f"""
# Target build for {chosen.description}: `make target`, then `make run-target`.
TARGET_CC = {cc}
TARGET_CFLAGS = {' '.join(target_cflags(chosen))}
TARGET_SOURCES = src/{name}_casadi.c src/{name}.c target/board.c target/harness.c

target: target/harness.elf

target/harness.elf: $(TARGET_SOURCES)
\t$(TARGET_CC) $(TARGET_CFLAGS) -Iinclude -Itarget {link} -o $@ $(TARGET_SOURCES) {' '.join(LIBRARIES)}

run-target: target/harness.elf
\t{run}

.PHONY: target run-target
"""
