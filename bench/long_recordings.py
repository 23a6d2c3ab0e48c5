"""Long recordings from the real LWR4+ runs (shared/data/lwr4-real, 25 s each at 200 Hz): the
run repeated end to end (time continued at the recording's step), optionally resampled to a
higher rate by linear interpolation of every column, written as CSV or Parquet.

    python bench/long_recordings.py OUT.csv --minutes 5 [--rate 1000] [--source FILE]

Real sensor data (quantisation, noise, friction as they are); the joins between repeats are
jumps of a few hundredths of a radian, as in a log that was cut and restarted.
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from common import ROOT, arguments

SOURCE = ROOT / "examples" / "lwr4-real" / "measurement_1.csv"
CHUNK = 100000  # rows written at a time (the output may be larger than memory should hold)


def read_source(path: Path):
    header = path.read_text().partition("\n")[0].strip().split(",")
    return header, np.loadtxt(path, delimiter=",", skiprows=1)


def tiled_rows(data: np.ndarray, rows: int, rate: float | None):
    """Blocks of (<= CHUNK, columns) rows of the repeated run; column 0 is time."""
    t = data[:, 0]
    step = float(np.median(np.diff(t)))
    period = t[-1] - t[0] + step
    if rate:  # resample one period on the finer clock, once
        fine = np.arange(0.0, period - 1e-12, 1.0 / rate)
        inside = np.clip(fine, t[0], t[-1])
        data = np.column_stack([fine] + [np.interp(inside, t, data[:, k]) for k in range(1, data.shape[1])])
        step = 1.0 / rate
        period = data.shape[0] * step
    one = data.shape[0]
    done = 0
    while done < rows:
        k = np.arange(done, min(done + CHUNK, rows))
        block = data[k % one].copy()
        block[:, 0] = k * step  # one clock: no jumps in time at the joins
        yield block
        done += k.size


def write(out: Path, minutes: float, rate: float | None = None, source: Path = SOURCE) -> int:
    header, data = read_source(source)
    step = 1.0 / rate if rate else float(np.median(np.diff(data[:, 0])))
    rows = int(round(minutes * 60 / step))
    out.parent.mkdir(parents=True, exist_ok=True)
    if out.suffix == ".parquet":
        import pyarrow as pa
        import pyarrow.parquet as pq

        schema = pa.schema([(h, pa.float64()) for h in header])
        with pq.ParquetWriter(out, schema) as w:
            for block in tiled_rows(data, rows, rate):
                w.write_table(pa.table({h: block[:, k] for k, h in enumerate(header)}, schema=schema))
        return rows
    with open(out, "w") as f:
        f.write(",".join(header) + "\n")
        for block in tiled_rows(data, rows, rate):
            np.savetxt(f, block, delimiter=",", fmt="%.9g")
    return rows


def main(argv=None) -> int:
    ap = arguments(__doc__)
    ap.add_argument("out", type=Path)
    ap.add_argument("--minutes", type=float, required=True)
    ap.add_argument("--rate", type=float, default=None, help="resample to this rate [Hz] (default: as recorded)")
    ap.add_argument("--source", type=Path, default=SOURCE)
    args = ap.parse_args(argv)
    rows = write(args.out, args.minutes, args.rate, args.source)
    print(f"{args.out}: {rows} rows", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
