"""Run a command as a child process and measure its wall time and peak memory.

Peak memory is the child's maximum resident set size as the kernel reports it to the
parent through wait4(): the largest RSS of the child or of any descendant it waited for
(Linux folds the waited-for descendants' maximum into the child's). It is not the sum of
processes that run at the same time (threads share one RSS, so a multithreaded step is
counted whole). Measuring in a child keeps the benchmark driver's own memory out of it.
"""
from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass


@dataclass
class Measured:
    returncode: int
    seconds: float
    max_rss_kib: int  # ru_maxrss is in KiB on Linux
    stdout: str
    stderr: str

    @property
    def max_rss_mib(self) -> float:
        return self.max_rss_kib / 1024.0


def run_measured(cmd, cwd=None, env=None) -> Measured:
    """Run cmd (a list), wait for it with os.wait4 and return its time, peak RSS and output.
    The output goes through temporary files, not pipes, so a chatty child cannot block."""
    with tempfile.TemporaryFile("w+") as out, tempfile.TemporaryFile("w+") as err:
        start = time.perf_counter()
        proc = subprocess.Popen([str(c) for c in cmd], stdout=out, stderr=err, cwd=cwd, env=env, text=True)
        _, status, usage = os.wait4(proc.pid, 0)
        seconds = time.perf_counter() - start
        proc.returncode = os.waitstatus_to_exitcode(status)  # reaped here; Popen must not wait again
        out.seek(0)
        err.seek(0)
        return Measured(proc.returncode, seconds, int(usage.ru_maxrss), out.read(), err.read())


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
    print(f"exit {m.returncode}, {m.seconds:.2f} s, peak RSS {m.max_rss_mib:.1f} MiB", file=sys.stderr)
    return m.returncode


if __name__ == "__main__":
    sys.exit(main())
