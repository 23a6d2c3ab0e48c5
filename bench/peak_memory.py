"""Run a command as a child process and measure its wall time and peak memory.

Peak memory is the maximum resident set size the kernel reports through wait4(): the
largest RSS of the command or of any descendant it waited for (Linux folds the waited-for
descendants' maximum in). It is not the sum of processes that run at the same time
(threads share one RSS, so a multithreaded step is counted whole).

Why a launcher: Linux also counts, in a new process's maximum RSS, the RSS of the process
it was forked (or vforked) from, up to the exec. Spawned straight from a benchmark driver
that has imported SymPy or Pinocchio, every child would report at least the driver's size.
So the command is spawned from a minimal Python (`python -S`, only `os` and `json`
imported) and that launcher's own peak RSS, about 10 MiB, is the floor of every measurement;
it is reported as `floor_kib`.
"""
from __future__ import annotations

import json
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass

# Runs in the minimal launcher process: spawn argv[2:], wait for it, write the numbers to argv[1].
LAUNCHER = """
import json, os, sys
# The launcher's own peak (VmHWM); getrusage(RUSAGE_SELF) would include what it inherited.
with open("/proc/self/status") as f:
    floor = next((int(line.split()[1]) for line in f if line.startswith("VmHWM:")), 0)
pid = os.posix_spawnp(sys.argv[2], sys.argv[2:], os.environ)
_, status, usage = os.wait4(pid, 0)
with open(sys.argv[1], "w") as f:
    json.dump({"returncode": os.waitstatus_to_exitcode(status), "max_rss_kib": usage.ru_maxrss,
               "floor_kib": floor, "cpu_seconds": usage.ru_utime + usage.ru_stime}, f)
"""


@dataclass
class Measured:
    returncode: int
    seconds: float
    max_rss_kib: int  # ru_maxrss is in KiB on Linux
    floor_kib: int  # the launcher's own RSS: a measurement at this value means "at most this"
    cpu_seconds: float  # user + system CPU time of the command and its waited-for descendants
    stdout: str
    stderr: str

    @property
    def max_rss_mib(self) -> float:
        return self.max_rss_kib / 1024.0


def run_measured(cmd, cwd=None, env=None) -> Measured:
    """Run cmd (a list) through the launcher; return its time, peak RSS and output. The
    output goes through temporary files, not pipes, so a chatty child cannot block."""
    with tempfile.TemporaryFile("w+") as out, tempfile.TemporaryFile("w+") as err, \
            tempfile.NamedTemporaryFile("r", suffix=".json") as numbers:
        start = time.perf_counter()
        subprocess.run([sys.executable, "-S", "-c", LAUNCHER, numbers.name, *(str(c) for c in cmd)],
                       stdout=out, stderr=err, cwd=cwd, env=env, check=False)
        seconds = time.perf_counter() - start
        text = numbers.read()
        out.seek(0)
        err.seek(0)
        if not text:
            raise OSError(f"could not run {cmd[0]}: {err.read().strip()}")
        got = json.loads(text)
        return Measured(got["returncode"], seconds, got["max_rss_kib"], got["floor_kib"], got["cpu_seconds"],
                        out.read(), err.read())


def main(argv=None) -> int:
    """python bench/peak_memory.py CMD ...: run CMD, then print its wall time and peak RSS."""
    argv = sys.argv[1:] if argv is None else argv
    if not argv:
        print("usage: python bench/peak_memory.py COMMAND [ARGS ...]", file=sys.stderr)
        return 2
    m = run_measured(argv)
    sys.stdout.write(m.stdout)
    sys.stdout.flush()
    sys.stderr.write(m.stderr)
    print(f"exit {m.returncode}, {m.seconds:.2f} s, peak RSS {m.max_rss_mib:.1f} MiB "
          f"(floor {m.floor_kib / 1024:.1f} MiB)", file=sys.stderr)
    return m.returncode


if __name__ == "__main__":
    sys.exit(main())
