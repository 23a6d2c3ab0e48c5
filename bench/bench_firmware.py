"""Firmware build report: the generated C cross-compiled for ARM Cortex-M4F and Cortex-M7.

    python bench/bench_firmware.py                         # generated/lwr -> bench/results/firmware.md
    python bench/bench_firmware.py --folder DIR --out FILE

For every target (M4F: single-precision FPU; M7: double-precision FPU), precision (float
with -D<ROBOT>_USE_FLOAT, double) and optimisation level (-Os, -O2), each library source is
compiled with Debian's arm-none-eabi-gcc, -std=c99 -ffreestanding -fstack-usage and warnings
as errors (-Wdouble-promotion too in float, so no computation silently goes double). Reported:
.text per object and in total, .data + .bss (no globals: 0), the worst stack use of every
function (-fstack-usage; all generated functions are leaves apart from libm calls, so their
own frame is their stack use plus that of sin/cos), and the undefined symbols: only libm and
the compiler's helpers (__aeabi_*: on the M4F, double arithmetic is software floating point).
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
import tempfile
from pathlib import Path

from common import ROOT, arguments

CC = "arm-none-eabi-gcc"
TARGETS = {
    "Cortex-M4F": ["-mcpu=cortex-m4", "-mthumb", "-mfpu=fpv4-sp-d16", "-mfloat-abi=hard"],
    "Cortex-M7": ["-mcpu=cortex-m7", "-mthumb", "-mfpu=fpv5-d16", "-mfloat-abi=hard"],
}
PRECISIONS = ("float", "double")
LEVELS = ("-Os", "-O2")
STRICT = ["-std=c99", "-ffreestanding", "-fstack-usage", "-Wall", "-Wextra", "-Werror", "-pedantic"]


def library_sources(folder: Path) -> list[Path]:
    return [folder / name for name in json.loads((folder / "manifest.json").read_text())["files"]["library"]]


def build(folder: Path, target: str, precision: str, level: str, work: Path) -> dict:
    """Compile the library sources for one configuration; sizes, stack per function, undefined symbols."""
    robot = json.loads((folder / "manifest.json").read_text())["robot"]
    flags = [*TARGETS[target], level, *STRICT]
    if precision == "float":
        flags += [f"-D{robot.upper()}_USE_FLOAT", "-Wdouble-promotion"]
    work.mkdir(parents=True, exist_ok=True)
    text, data, stack, undefined, sizes = {}, 0, {}, set(), {}
    for source in library_sources(folder):
        obj = work / (source.stem + ".o")
        subprocess.run([CC, *flags, "-I", str(folder), "-c", str(source), "-o", str(obj)], check=True,
                       capture_output=True, text=True)
        # Berkeley format: text data bss dec hex filename
        fields = subprocess.run(["arm-none-eabi-size", str(obj)], check=True, capture_output=True,
                                text=True).stdout.splitlines()[1].split()
        text[source.name] = int(fields[0])
        data += int(fields[1]) + int(fields[2])
        for line in obj.with_suffix(".su").read_text().splitlines():  # file:line:col:function<TAB>bytes<TAB>kind
            where, size, kind = line.split("\t")
            stack[where.rsplit(":", 1)[-1]] = (int(size), kind)
        nm = subprocess.run(["arm-none-eabi-nm", "-u", str(obj)], check=True, capture_output=True, text=True).stdout
        undefined |= {line.split()[-1] for line in nm.splitlines() if line.strip()}
        # code size of each function: nm -S prints "address size type name" for defined symbols
        nm = subprocess.run(["arm-none-eabi-nm", "-S", "--defined-only", str(obj)], check=True, capture_output=True,
                            text=True).stdout
        for line in nm.splitlines():
            fields = line.split()
            if len(fields) == 4 and fields[2] in "tT":
                sizes[fields[3]] = int(fields[1], 16)
    return {"text": text, "data_bss": data, "stack": stack, "undefined": sorted(undefined), "sizes": sizes}


def report(folder: Path, results: dict, compiler: str) -> str:
    configs = list(results)
    robot = json.loads((folder / "manifest.json").read_text())["robot"]
    sources = list(next(iter(results.values()))["text"])
    lines = [f"# Firmware build of `{folder.relative_to(ROOT) if folder.is_relative_to(ROOT) else folder}`", "",
             f"`python bench/bench_firmware.py`; {compiler}; flags `{' '.join(STRICT)}` plus the target's",
             "(M4F: `" + " ".join(TARGETS["Cortex-M4F"]) + "`, M7: `" + " ".join(TARGETS["Cortex-M7"]) + "`),",
             f"the level, and `-D{robot.upper()}_USE_FLOAT -Wdouble-promotion` for float.",
             "The M4F's FPU is single precision only: its double build does every double operation in",
             "software (`__aeabi_d*` helper calls), so prefer the float build there.", "",
             "## Code size (.text, bytes) and undefined symbols", "",
             "| target | precision | level | " + " | ".join(f"`{s}`" for s in sources)
             + " | total | .data + .bss | undefined symbols |",
             "|---|---|---|" + "---:|" * (len(sources) + 2) + "---|"]
    for (target, precision, level), r in results.items():
        helpers = [s for s in r["undefined"] if s.startswith("__aeabi_")]
        others = [s for s in r["undefined"] if not s.startswith("__aeabi_")]
        described = ", ".join(others) + (f"; software floating point: {', '.join(helpers)}" if helpers else "")
        lines.append(f"| {target} | {precision} | {level} | " + " | ".join(str(r["text"][s]) for s in sources)
                     + f" | {sum(r['text'].values())} | {r['data_bss']} | {described} |")
    functions = list(next(iter(results.values()))["stack"])
    lines += ["", "## Code size per function (.text bytes, `nm -S`)", "",
              "| function | " + " | ".join(f"{t} {p} {lv}" for t, p, lv in configs) + " |",
              "|---|" + "---:|" * len(configs)]
    for fn in functions:
        lines.append(f"| `{fn}` | " + " | ".join(str(results[c]["sizes"].get(fn, "-")) for c in configs) + " |")
    lines += ["", "## Stack use per function (bytes, `-fstack-usage`)", "",
              "Every function's own frame; all are `static` (known at compile time). Add the stack of",
              "`sin`/`cos` (libm) for the functions that call them.", "",
              "| function | " + " | ".join(f"{t} {p} {lv}" for t, p, lv in configs) + " |",
              "|---|" + "---:|" * len(configs)]
    for fn in functions:
        lines.append(f"| `{fn}` | " + " | ".join(str(results[c]["stack"][fn][0]) for c in configs) + " |")
    lines.append("| **worst** | " + " | ".join(
        f"**{max(v[0] for v in results[c]['stack'].values())}**" for c in configs) + " |")
    kinds = {kind for r in results.values() for _, kind in r["stack"].values()}
    lines += ["", f"Stack kinds reported: {', '.join(sorted(kinds))}.", ""]
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = arguments(__doc__)
    parser.add_argument("--folder", type=Path, default=ROOT / "generated" / "lwr")
    parser.add_argument("--out", type=Path, default=ROOT / "bench" / "results" / "firmware.md")
    args = parser.parse_args(argv)
    compiler = subprocess.run([CC, "--version"], check=True, capture_output=True, text=True).stdout.splitlines()[0]
    results = {}
    with tempfile.TemporaryDirectory() as tmp:
        for target in TARGETS:
            for precision in PRECISIONS:
                for level in LEVELS:
                    work = Path(tmp) / re.sub(r"\W", "_", f"{target}_{precision}_{level}")
                    r = build(args.folder.resolve(), target, precision, level, work)
                    results[(target, precision, level)] = r
                    print(f"{target:10} {precision:6} {level}: .text {sum(r['text'].values()):6d} B, "
                          f"worst stack {max(v[0] for v in r['stack'].values()):5d} B, "
                          f"undefined {', '.join(s for s in r['undefined'] if not s.startswith('__aeabi_'))}"
                          f" + {sum(s.startswith('__aeabi_') for s in r['undefined'])} __aeabi_*")
    text = report(args.folder.resolve(), results, compiler)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(text)
    print(f"written: {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
