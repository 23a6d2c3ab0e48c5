"""A recording as a logger wrote it, made into samples of one regular clock before filtering: repeated
rows left out, held columns interpolated between their updates, jittered stamps replaced by the
clock, uneven ones interpolated onto a regular grid (docs/measured-data.md, "Logs as loggers write them").

    recording, report = regular_samples(recording)      # report.notes, report.warnings"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np
from scipy.interpolate import CubicSpline

from . import glitches
from .as_written import same_as_before
from .recording import Recording

UNEVEN = 0.01  # steps differing from the median by more than this share are not one grid
HELD_MEDIAN = 2  # a block whose updates are this many rows apart (median) is at a lower rate
LONG_GAP = 10  # a step of more than this many is a gap: filled for the filter, its samples not data (Signals.inner)
REPEATS_WORTH_SAYING = 0.001  # share of rows
JITTER_SHARE = 0.45  # of a step: stamps further from the clock than this are not jitter
ROUGHER = 0.5  # the clock is used when the positions' jerk energy over it is below this share
COMB_ROWS = 4096  # rows whose short steps find a polling logger's clock (_polled)
POLLED_ROWS = 60000  # _polled's search holds 121 trial clocks of every row: longer recordings keep their stamps


@dataclass
class LogReport:
    repeated: int = 0  # rows left out as repeats of the row before (with their stamp or another)
    held: dict = field(default_factory=dict)  # block -> median rows between its updates
    filled: int = 0  # samples interpolated onto the grid where the log had none
    longest_gap: float = 0.0  # s
    gaps: list = field(default_factory=list)  # (start, end) s of each step over LONG_GAP steps: filled for the filter only
    clock: str | None = None  # regular_clock's note, when the stamps were replaced by a clock
    notes: list = field(default_factory=list)
    warnings: list = field(default_factory=list)


def _blocks(r: Recording) -> dict:
    out = {"q": r.q}
    for name in ("qd", "qdd", "tau"):
        if getattr(r, name) is not None:
            out[name] = getattr(r, name)
    return out


def _all_columns(r: Recording) -> np.ndarray:
    parts = list(_blocks(r).values()) + [np.asarray(v, dtype=float)[:, None] for v in r.extra.values()]
    return np.hstack(parts)


def _mapped(r: Recording, t: np.ndarray, f) -> Recording:
    """r at times t, f applied to every column block."""
    def of(x):
        return None if x is None else f(np.asarray(x, dtype=float))

    return dataclasses.replace(r, t=t, q=of(r.q), tau=of(r.tau), qd=of(r.qd), qdd=of(r.qdd),
                               extra={k: of(v) for k, v in r.extra.items()})


def repeated_rows(r: Recording) -> np.ndarray:
    """Boolean (T,): rows repeating the row before in every column while the positions move."""
    repeats, _ = _repeats(_all_columns(r), r.q)
    return repeats


def _repeats(data: np.ndarray, q: np.ndarray, before=None) -> tuple[np.ndarray, int]:
    """(repeats, the first row of a run at the end): a run counts when the row after it has other positions."""
    same = same_as_before(data, before)
    other = np.flatnonzero(~same)  # rows that are no repeat of the row before
    end = int(other[-1]) + 1 if other.size else 0  # from here on, repeats with no row after them yet
    after = other[np.minimum(np.searchsorted(other, np.arange(end), side="right"), other.size - 1)]
    moving = np.zeros(data.shape[0], dtype=bool)  # the row after each run has other positions than the run
    moving[:end] = np.any(q[after] != q[np.maximum(after - 1, 0)], axis=1)
    return same & moving, end


class Streamed:
    """regular_samples' repeated rows for a recording read in blocks (data/chunks.py): left out
    block by block, a run of repeats at a block's end held back until the row after it (in a later
    block) says whether the arm moved. Held columns and jittered stamps need the whole recording:
    they are told in one warning, not repaired. Use: for block in streamed.blocks(chunks(...))."""

    def __init__(self):
        self.report, self.rows = LogReport(), 0

    def blocks(self, blocks):
        before, pending, name = None, None, ""
        for block in blocks:
            _as_read(self.report, block, say=not self.report.notes)  # its note said once, by the first block
            name, r = block.name, (block if pending is None else _joined(pending, block))
            data = _all_columns(r)
            repeats, end = _repeats(data, r.q, before)
            self.report.repeated += int(repeats[:end].sum())
            pending = _mapped(r, r.t[end:], lambda x: x[end:]) if end < r.t.size else None
            if end:
                before, keep = data[end - 1], ~repeats[:end]
                done = _mapped(r, r.t[:end][keep], lambda x: x[:end][keep])
                self.rows += done.t.size
                self._check(done)  # without the repeats, as regular_samples looks at them
                yield done
        if pending is not None:  # a run at the very end is kept
            self.rows += pending.t.size
            yield pending
        _say_repeats(self.report, name, self.rows)

    def _check(self, block) -> None:
        if block.t.size < 16 or self.report.warnings:
            return
        held, jitter = held_blocks(block), regular_clock(block.t, block.q)[1]
        if held or jitter:
            what = ", ".join(f"{k} updated every {v:g} rows" for k, v in held.items()) or "time stamps jitter"
            self.report.warnings.append(f"{block.name}: {what}; read in blocks, this is not repaired (the whole-recording "
                                        "repairs run where the recording is read whole: within --max-rows)")


def _say_repeats(report: LogReport, name: str, kept: int) -> None:
    if report.repeated:
        share = report.repeated / (report.repeated + kept)
        report.notes.insert(0, f"{report.repeated} repeated rows ({100 * share:.2g} %: the same sample written twice) "
                            "left out")
        if share > REPEATS_WORTH_SAYING:
            report.warnings.insert(0, f"{name}: {report.repeated} rows ({100 * share:.2g} %) repeat the row before "
                                   "while the arm moves (a logger writing one sample twice): left out")


def _as_read(report: LogReport, r: Recording, say: bool = True) -> None:
    """What reading did (data/as_written.py): rows that copied the row before, stamp included, counted with
    the repeats; its note (rows missing values at the ends, stamps in ms, us, ns or Unix time) said."""
    report.repeated += r.copies
    if r.read_note and say:
        report.notes.append(r.read_note)
        report.warnings.append(f"{r.name}: {r.read_note}")


def _joined(a: Recording, b: Recording) -> Recording:
    cat = (lambda x, y: None if x is None else np.concatenate([x, y]))
    return dataclasses.replace(b, t=cat(a.t, b.t), q=cat(a.q, b.q), tau=cat(a.tau, b.tau), qd=cat(a.qd, b.qd),
                               qdd=cat(a.qdd, b.qdd), extra={k: cat(a.extra[k], v) for k, v in b.extra.items()})


def held_blocks(r: Recording) -> dict:
    """{block: median rows between its updates} for blocks updated at a lower rate than the rows."""
    out = {}
    for name, x in _blocks(r).items():
        changed = np.flatnonzero(np.any(x[1:] != x[:-1], axis=1)) + 1
        if changed.size < 8:
            continue
        every = float(np.median(np.diff(changed)))
        if every >= HELD_MEDIAN:
            out[name] = every
    return out


def _unheld(t: np.ndarray, x: np.ndarray) -> np.ndarray:
    """x interpolated linearly between the rows where it changes (its update times)."""
    changed = np.concatenate([[0], np.flatnonzero(np.any(x[1:] != x[:-1], axis=1)) + 1])
    return np.column_stack([np.interp(t, t[changed], x[changed, j]) for j in range(x.shape[1])])


def regular_samples(r: Recording, regrid: bool = True) -> tuple[Recording, LogReport]:
    """regrid False: uneven stamps are kept (no filter follows; differences over uneven times are exact)."""
    report = LogReport()
    _as_read(report, r)
    if r.t.size < 16:
        return r, report
    repeats = repeated_rows(r)
    if repeats.any():
        report.repeated += int(repeats.sum())
        r = _mapped(r, r.t[~repeats], lambda x: x[~repeats])
    _say_repeats(report, r.name, r.t.size)
    r, found = glitches.repaired(r)  # wrapped angles, spikes: before held columns and the clock look at the rows
    report.notes += found
    report.warnings += [f"{r.name}: {x}" for x in found]
    held = held_blocks(r)
    for name, every in held.items():
        setattr(r, name, _unheld(r.t, getattr(r, name)))
        rate = 1.0 / float(np.median(np.diff(r.t)))
        report.notes.append(f"{name} updated every {every:g} rows (about {rate / every:.3g} Hz in a {rate:.3g} Hz log): "
                            "interpolated between its updates")
        report.warnings.append(f"{r.name}: mixed rates: {name} is updated only every {every:g} rows; interpolated "
                               "between its updates")
    report.held = held
    t, note = regular_clock(r.t, r.q)
    if note:
        report.clock = note
        r = dataclasses.replace(r, t=t)
    steps = np.diff(r.t)
    period = float(np.median(steps))
    if regrid and np.max(np.abs(steps - period)) > UNEVEN * period:
        count = int(round((r.t[-1] - r.t[0]) / period))
        grid = r.t[0] + period * np.arange(count + 1)
        grid = grid[grid <= r.t[-1] + 1e-9 * period]
        report.filled = max(grid.size - r.t.size, 0)
        report.longest_gap = float(steps.max())
        report.gaps = [(float(r.t[i]), float(r.t[i + 1])) for i in np.flatnonzero(steps > LONG_GAP * period)]
        r = _mapped(r, grid, lambda x, t=r.t: CubicSpline(t, x, axis=0)(grid))
        within = ", those in long gaps for the filter only, not as data" if report.gaps else ""
        report.notes.append(f"stamps uneven (steps {1e3 * float(steps.min()):.3g}-{1e3 * float(steps.max()):.3g} ms): "
                            f"interpolated onto a regular {1e3 * period:.4g} ms grid ({report.filled} samples "
                            f"filled{within})")
    return r, report


def regular_clock(t: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, str | None]:
    """Sample times as the recording's clock took them, not as a logger stamped them when it wrote
    them (the real LWR4+ recordings: 5 ms steps with pairs of 6.5 + 3.4 ms, a spike in the
    differentiated acceleration at every pair): the clock t0 + k T (k counted from the stamps, so a
    dropped sample stays a gap) when every stamp lies within JITTER_SHARE of a step from it, the
    stamps differ from it, and the positions' jerk over it carries less than ROUGHER of its energy
    over the stamps; otherwise the stamps and None."""
    t = np.asarray(t, dtype=float)
    if t.size < 16:
        return t, None
    steps = np.diff(t)
    # ticks counted step by step (a late stamp and the early one after it are one tick each;
    # a step of two periods is a dropped sample), so that a slow drift of the stamps cannot
    # make two samples one tick
    k = np.concatenate([[0.0], np.cumsum(np.maximum(np.round(steps / np.median(steps)), 1.0))])
    # The clock's period and phase as medians: most stamps are on time, and a logger's are
    # late, never early, so a mean (a line fit) would put the clock late by their average delay.
    half = t.size // 2
    period = float(np.median((t[half:2 * half] - t[:half]) / (k[half:2 * half] - k[:half])))
    clock = float(np.median(t - k * period)) + k * period
    off = np.abs(t - clock)
    if off.max() > JITTER_SHARE * period:
        counted, note = _counted(t, q)
        return (counted, note) if note else _polled(t, q)
    if off.max() <= 1e-6 * period:
        return t, None
    if _roughness(clock, q) >= ROUGHER * _roughness(t, q):
        return t, None
    return clock, (f"time stamps jitter by up to {1e3 * off.max():.2g} ms around a regular {1e3 * period:.4g} ms "
                   "clock; the positions are smooth over the clock, not over the stamps: the clock is used")


def _counted(t: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, str | None]:
    """Every row one tick of a regular clock, as a logger that drops no sample but stamps each on
    arrival writes them (its latency wandering by more than JITTER_SHARE of a step): used when the
    positions' jerk over it carries less than ROUGHER of its energy over the stamps (a dropped
    sample, a gap or a stall makes it rough) and its step is the stamps' median step within UNEVEN
    (a polling logger's rows, repeats left out, miss the samples it dropped: 5 % fewer rows than ticks,
    and one tick per row would drift by many steps)."""
    count = t[0] + (t[-1] - t[0]) * np.arange(t.size) / (t.size - 1)
    if abs((count[1] - count[0]) / np.median(np.diff(t)) - 1.0) > UNEVEN:  # rows fewer than ticks: samples dropped
        return t, None
    if _roughness(count, q) >= ROUGHER * _roughness(t, q):
        return t, None
    return count, (f"time stamps wander by up to {1e3 * float(np.max(np.abs(t - count))):.2g} ms off a regular "
                   f"{1e3 * float(count[1] - count[0]):.4g} ms clock that has one sample per row; the positions are "
                   "smooth over that clock, not over the stamps: the clock is used")


def _polled(t: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, str | None]:
    """A logger polling the latest sample on its own clock writes each row up to a period after the
    sample it holds (tests/simulation/logger.py polled: at 100 Hz its 3 ms delays wander over the
    whole period): each row is the last tick of the clock phase + k T at or before its stamp. The
    period and phase: the shortest steps (a tick between their rows) as a comb, its strongest
    period; then, for periods around it, the latest phase below every stamp; the smoothest clock
    that gives every row its own tick, used when smoother than the stamps by ROUGHER."""
    if t.size > POLLED_ROWS:
        return t, None
    head = t[:COMB_ROWS]  # the comb on the first rows (its cost grows as their count squared), the search
    steps, span, centre = np.diff(head), head[-1] - head[0], 0.5 * (head[0] + head[-1])  # below over every row
    middle = (0.5 * (head[1:] + head[:-1]) - centre)[steps < np.quantile(steps, 0.3)]
    median = float(np.median(steps))
    fine = median * median / (8.0 * span)  # the comb's phase at the end moves by 1/8 turn

    def comb(periods):
        return np.exp(2j * np.pi * middle[None, :] / periods[:, None]).sum(axis=1)

    periods = np.arange(0.75 * median, 1.02 * median, fine)
    strength = np.concatenate([np.abs(comb(periods[i:i + 256])) for i in range(0, periods.size, 256)])
    periods = periods[np.argmax(strength)] + np.linspace(-fine, fine, 65)
    z = comb(periods)
    period = float(periods[np.argmax(np.abs(z))])
    start = centre + period * float(np.angle(z[np.argmax(np.abs(z))])) / (2.0 * np.pi)
    best, tried = None, np.linspace(-0.06, 0.06, 121)[:, None]
    for step in period * (1.0 + np.linspace(-5e-5, 5e-5, 101)):  # within 1/200 of a period at the ends
        phases = start + tried * step
        ticks = np.floor((t[None, :] - phases) / step)
        whole = phases[np.all(np.diff(ticks, axis=1) > 0, axis=1), 0]  # every row its own tick
        if whole.size:
            clock = step * ticks[np.argmin(np.abs(phases[:, 0] - np.median(whole)))] + np.median(whole)
            best = min(best or (np.inf, clock), (_roughness(clock, q), clock), key=lambda x: x[0])
    if best is None or best[0] >= ROUGHER * _roughness(t, q):
        return t, None
    clock = best[1]
    return clock, (f"time stamps late by up to {1e3 * float(np.max(t - clock)):.2g} ms after the samples of a regular "
                   f"{1e3 * float(np.median(np.diff(clock))):.4g} ms clock (a logger polling the latest sample); the "
                   "positions are smooth over the clock, not over the stamps: the clock is used")


def _roughness(t: np.ndarray, q: np.ndarray) -> float:
    """Median over joints of the energy of the positions' third derivative over times t."""
    jerk = np.gradient(np.gradient(np.gradient(q, t, axis=0), t, axis=0), t, axis=0)
    return float(np.median(np.sum(jerk ** 2, axis=0)))
