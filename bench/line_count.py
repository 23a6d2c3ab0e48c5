"""The lines of the measured-data half (issue 26 asks it to be shorter than at filing): per folder
at filing (334e664) and now, and the lines now of what was added after filing, each with the issue
it came from, so that a reader sees whether the code that existed at filing got shorter.

    python bench/line_count.py                 # the Markdown section of docs/design.md
    python bench/line_count.py --now REV       # another commit than HEAD

Lines are every line of the .py files (comments, docstrings and blank lines included), read from
git at each commit, so the figures do not depend on the working tree. What was added is a list
written by hand below (ADDED): whole modules, or module:function (its lines from `def` to its
end, by the ast). Where an addition was made in a module that existed at filing and is not a
function of its own (a branch, a field, a report line), it is not listed; and what is listed of
such a module counts at most as much as the module grew since filing (a function that replaced
older code is not all new). The "existing code" row is therefore, if anything, too high.
"""

from __future__ import annotations

import ast
import subprocess

from common import ROOT, arguments, table

FILING = "334e664"  # issue 26 filed (2026-12-02)
PACKAGE = "generator/dyngen"
FOUR = ("data", "identification", "excitation", "diagnosis")  # the issue's count at filing: 5,772 lines
LATER = ("terms", "streaming")  # made after filing: terms/ from code of the four (#26), streaming/ (#29)
# the measured-data commands (commands/ also holds generate and extract); not in the issue's count
COMMANDS = ("diagnose", "excite", "identify", "identify_consistent", "identify_least_squares", "long_diagnosis",
            "recordings", "survey")

# (issue, what, where): what issues 25 (real logs) and 29 (long recordings, many recordings) added
# after filing, where it lives now; the issue from the branch that brought it (h25/h32/h42: #25,
# h29/h31/h41: #29), found with `git log -S "def NAME"` and `git log --diff-filter=A -- FILE`.
ADDED = (
    (25, "logs as loggers write them", "data/log_quality.py"),
    (25, "noise from the spectrum (log quality)", "data/automatic.py:spectral_noise"),
    (25, "whether a log can be trusted (exit 3)", "data/trust.py"),
    (25, "what an unusable log writes", "diagnosis/diagnosis_files.py:write_unusable"),
    (25, "its figure", "diagnosis/diagnosis_files.py:_figure"),
    (25, "findings outside their physical range", "diagnosis/findings_check.py"),
    (25, "stability across stretches", "diagnosis/stable.py"),
    (25, "control run, gating, effects the links explain", "diagnosis/across.py"),
    (25, "the re-identification gate's sample and fit", "diagnosis/reidentify.py:sampled"),
    (25, "", "diagnosis/reidentify.py:rigid_fit"),
    (25, "", "diagnosis/reidentify.py:link_corrections"),
    (25, "why the re-identification was not tried", "diagnosis/pipeline.py:_why_not_tried"),
    (25, "identify's sanity checks", "identification/sanity.py"),
    (25, "rows copied, missing values at the ends, the time column's unit and origin", "data/as_written.py"),
    (25, "", "data/recording.py:checked_rows"),
    (25, "recorded velocities against the positions", "data/conditioning.py:_velocity_disagrees"),
    (25, "what a rigid body can explain (links off, not the log)", "data/rigid_fit.py"),
    (25, "a bus's errors: spikes, angles that wrap", "data/glitches.py"),
    (25, "noise that is not white: the model filtered alike", "data/automatic.py:coloured"),
    (25, "headers as numpy, pandas and loggers write them", "data/recording.py:header_of"),
    (25, "", "data/recording.py:_numeric"),
    (29, "recordings in blocks", "data/chunks.py"),
    (29, "Parquet and ROS 2 bags", "data/columnar.py"),
    (29, "", "data/rosbag.py"),
    (29, "one reader for every format", "data/reader.py"),
    (29, "globs", "data/paths.py"),
    (29, "a recording from any format's columns", "data/recording.py:from_columns"),
    (29, "", "data/recording.py:csv_line"),
    (29, "consistent identify in blocks", "identification/blocks.py"),
    (29, "", "identification/triangular.py"),
    (29, "normal equations from blocks", "identification/normal.py:Swaps"),
    (29, "statistics from blocks", "identification/statistics.py:_Correlation"),
    (29, "", "identification/statistics.py:_score_rows"),
    (29, "", "identification/statistics.py:_score_blocks"),
    (29, "least squares from a QR factor", "identification/least_squares.py:fit_factor"),
    (29, "every row of long recordings", "diagnosis/every_row.py"),
    (29, "blocks, workers, Dask, the gap survey, sampling", "streaming/"),
)


def git(*args: str) -> str:
    return subprocess.run(["git", *args], cwd=ROOT, capture_output=True, text=True, check=True).stdout


def modules(rev: str, folder: str) -> dict:
    """path below generator/dyngen/ -> text, for the .py files of folder at rev."""
    names = git("ls-tree", "-r", "--name-only", rev, "--", f"{PACKAGE}/{folder}").split()
    return {n[len(PACKAGE) + 1:]: git("show", f"{rev}:{n}") for n in names if n.endswith(".py")}


def lines(texts) -> int:
    return sum(len(t.splitlines()) for t in texts)


def function_lines(text: str, name: str) -> int:
    """Lines of the module-level function or class `name` (decorators included)."""
    for node in ast.parse(text).body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)) and node.name == name:
            first = min([node.lineno, *(d.lineno for d in node.decorator_list)])
            return node.end_lineno - first + 1
    raise SystemExit(f"line_count.py: no {name} any more: update ADDED")


def added_lines(where: str, now: dict) -> int:
    path, _, name = where.partition(":")
    if path.endswith("/"):
        return lines(t for p, t in now.items() if p.startswith(path))
    if path not in now:
        raise SystemExit(f"line_count.py: no {path} any more: update ADDED")
    return function_lines(now[path], name) if name else len(now[path].splitlines())


def report(now_rev: str) -> list[str]:
    then = {f: modules(FILING, f) for f in FOUR + LATER}
    now = {f: modules(now_rev, f) for f in FOUR + LATER}
    commands = {f"commands/{c}.py" for c in COMMANDS}
    commands_then = [t for p, t in modules(FILING, "commands").items() if p in commands]
    commands_now = [t for p, t in modules(now_rev, "commands").items() if p in commands]
    rows = [[f"{f}/", lines(then[f].values()), lines(now[f].values())] for f in FOUR + LATER]
    total_then, total_now = sum(r[1] for r in rows), sum(r[2] for r in rows)
    every = {p: t for f in FOUR + LATER for p, t in now[f].items()}
    grown = {p: len(t.splitlines()) - len(then[p.split("/")[0]].get(p, "").splitlines()) for p, t in every.items()}
    per_issue, added_rows, room = {}, [], {p: g for p, g in grown.items() if p in then[p.split("/")[0]]}
    for issue, what, where in ADDED:
        n = whole = added_lines(where, every)
        path = where.partition(":")[0]
        if path in room:  # a module that existed at filing: no more than it grew
            n = min(n, max(room[path], 0))
            room[path] -= n
        per_issue[issue] = per_issue.get(issue, 0) + n
        added_rows.append([f"#{issue}", what, f"`{where}`", n if n == whole else f"{n} (of its {whole}: the module grew less)"])
    added = sum(per_issue.values())
    existing = total_now - added
    verdict = ("shorter" if existing < total_then else "not shorter") + f" than at filing ({existing - total_then:+,})"
    out = [f"Lines of the .py files (comments and docstrings included), at filing ({FILING}) and now "
           f"({git('rev-parse', '--short', now_rev).strip()}); `python bench/line_count.py`.", ""]
    out += table(["folder", "at filing", "now"], "lrr",
                 rows + [["**the half**", f"**{total_then:,}**", f"**{total_now:,}**"],
                         ["commands (the measured-data ones, not counted above)", lines(commands_then),
                          lines(commands_now)]])
    out += ["", "What was added after filing, with the issue it came from (lines now):", ""]
    out += table(["issue", "what", "where", "lines"], "lllr", added_rows)
    out += ["", *table(["", "lines"], "lr", [
        *([f"added by #{i}", f"{n:,}"] for i, n in sorted(per_issue.items())),
        ["the half now", f"{total_now:,}"],
        ["the half now without what was added: the code that existed at filing", f"{existing:,}"],
        ["the half at filing", f"{total_then:,}"]])]
    out += ["", f"So the code that existed at filing is, now, {verdict}; the half as a whole is "
            f"{'shorter' if total_now < total_then else 'longer'} ({total_now - total_then:+,})."]
    return out


def main() -> None:
    parser = arguments(__doc__)
    parser.add_argument("--now", default="HEAD", metavar="REV", help="the commit counted as now (default HEAD)")
    print("\n".join(report(parser.parse_args().now)))


if __name__ == "__main__":
    main()
