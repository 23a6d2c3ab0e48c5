"""What the commands that take measured data share: the recording and conditioning flags,
reading and conditioning the recordings, and the compiled model (commands identify, diagnose,
excite)."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from ..arguments import whole
from ..data import columnar
from ..errors import InputError
from ..options import add_arguments, resolve

MIN_DIAGNOSIS_SAMPLES = 50
HELD_ROWS = 120000  # identify: recordings of more samples are read in blocks on every pass (10 min at 200 Hz)


def add_data_options(parser: argparse.ArgumentParser) -> None:
    from ..data import Conditioning

    parser.add_argument("robot", metavar="ROBOT.yaml", help="robot description (docs/conventions.md)")
    parser.add_argument("--data", action=Recordings, required=True, metavar="FILE",
                        help="a recording: CSV with header t, q1..qN, tau1..tauN, optional qd*, qdd*; or Parquet "
                             "(.parquet, the same columns); or a ROS 2 bag's folder (joint_states, joints by a URDF's names); "
                             "repeatable, and "
                             "a quoted glob ('logs/*.csv') stands for every file it matches")
    parser.add_argument("--effort-topic", metavar="TOPIC",
                        help="ROS 2 bags: take the torques from this topic (a commanded effort: JointState or "
                             "Float64MultiArray) instead of joint_states' measured effort")
    add_arguments(parser.add_argument_group("signal conditioning"), Conditioning)
    group = parser.add_argument_group("many recordings (identify --ols, --kind gravity or inertia; diagnose --survey: "
                                      "each recording read in blocks, in a worker)")
    group.add_argument("--workers", type=whole(1, 1024), metavar="N",
                       help="worker processes for the per-recording work (default: one per core, at most one per "
                            "recording)")
    group.add_argument("--scheduler", metavar="ADDRESS",
                       help="run the per-recording work on this Dask distributed scheduler (e.g. tcp://host:8786; "
                            "the workers must see the files at the same paths)")
    parser.add_argument("--model", metavar="DIR",
                        help="an already generated folder of this robot (default: generate it first)")
    parser.add_argument("-q", "--quiet", action="store_true", help="print nothing but errors and warnings")


class Recordings(argparse._AppendAction):
    """--data: appends the file, or every file a glob matches (sorted); a glob matching
    nothing is an error naming it."""

    def __call__(self, parser, namespace, values, option_string=None):
        from ..data.paths import expand

        for path in expand([values]):
            super().__call__(parser, namespace, path, option_string)


def check_enough(recordings) -> None:
    for r in recordings:
        if len(r.t) < MIN_DIAGNOSIS_SAMPLES:
            raise InputError(r.name, "", f"{len(r.t)} samples; a diagnosis needs at least {MIN_DIAGNOSIS_SAMPLES} "
                             "(seconds of motion at the recording's rate)")


class _Sample:
    """streaming.sample.windows(path) of a recording (its defaults: 8192-row blocks, no conditioning),
    made from the blocks of its parse (blocks.Source.of_file, the same blocks): the same windows."""

    def __init__(self):
        from ..streaming.sample import Spread

        self.spread, self.name = Spread(), None

    def add(self, block) -> None:
        self.spread.add(block)
        self.name = block.name

    def windows(self) -> list:
        return self.spread.windows(self.name)


def long_enough(windows) -> list:
    """The windows of a recording read in blocks that can be diagnosed (a last short one is left out)."""
    return [w for w in windows if w.t.size >= MIN_DIAGNOSIS_SAMPLES]


def check_headers(paths, robot, args, require_torques: bool = True, required: tuple = ()) -> None:
    """Headers and first rows: a bad file fails before anything is announced."""
    from ..data.chunks import chunks

    for path in paths:
        next(chunks(path, robot.dof, require_torques, required, 64, bag_of(args, robot)))


def bag_of(args, robot):
    """How a ROS 2 bag is read (data.rosbag.BagReading): --effort-topic, and the URDF's joint names."""
    from ..data.rosbag import BagReading

    return BagReading(getattr(args, "effort_topic", None), tuple(robot.joint_names))


def conditioning_of(args):
    from ..data import Conditioning

    return resolve(Conditioning, args, {})


def conditioning_text(signals) -> str:
    """What conditioning did, per recording (the automatic choice differs between recordings)."""
    notes = sorted({s.note for s in signals})
    return notes[0] if len(notes) == 1 else "; ".join(f"{s.name}: {s.note}" for s in signals)


def compiled_model(args, robot, progress):
    """The compiled model: the given folder, or one generated now into a temporary folder."""
    from ..runtime import load

    if args.model:
        folder = Path(args.model)
        if not (folder / "manifest.json").exists():
            raise InputError(str(folder), "", "not a generated folder (no manifest.json)")
        model = load(folder)
        if model.manifest["robot"] != robot.name or model.manifest["dof"] != robot.dof:
            raise InputError(str(folder), "manifest.json", f"the folder is for {model.manifest['robot']}, "
                             f"not {robot.name} ({robot.dof} joints)")
        return model
    from ..generate import generate

    generated = generate(robot, None, progress)  # into the per-user cache, not the user's folders
    with progress.step("compile the generated C"):
        return load(generated.folder)


def read_all(paths, robot, args, require_torques=True, required=(), need_motion=True):
    """need_motion: the recordings must move some joint (a model of motion is fitted), not only
    hold one pose; with torques, some torque must be nonzero (an all-zero file fits nothing)."""
    from ..data import read_recording

    topic = bag_of(args, robot)
    return conditioned([read_recording(p, robot.dof, require_torques, required, topic) for p in paths], args,
                       need_motion)


def conditioned(recordings, args, need_motion: bool = True) -> list:
    """The recordings checked together (data.recording.check_informative), then each conditioned on its own."""
    from ..data import condition
    from ..data.recording import check_informative

    check_informative(recordings, need_motion)
    return [condition(r, conditioning_of(args)) for r in recordings]


def read_sources(paths, robot, args) -> list:
    """The recordings as the consistent identification reads them (identification/blocks.py):
    in blocks from the file where conditioning would use its columns as recorded (one pass now
    for its length and the checks of data.recording.check_informative), else read and
    conditioned whole."""
    from ..data import condition, read_recording
    from ..data.chunks import chunks
    from ..data.recording import Recording, check_informative
    from ..identification.blocks import Source
    from ..streaming.step import _local

    topic, conditioning = bag_of(args, robot), conditioning_of(args)
    read = []  # a Source read in blocks, or the Recording read whole
    for path in paths:
        first = next(chunks(path, robot.dof, True, (), 64, topic))
        sample = _Sample()  # the sanity check's windows, from the parse's blocks (no second read)
        source = Source.of_file(path, robot.dof, topic, tap=sample.add) if _local(first, conditioning) and \
            columnar.format_of(path) != "rosbag" else None
        streamed = source is not None and source.rows > getattr(args, "max_rows", HELD_ROWS)
        if streamed:
            source.sample = sample
        read.append(source if streamed else read_recording(path, robot.dof, True, (), topic))
    # what check_informative reads of a Source: a two-sample stand-in that moves and has torques as the file does
    check_informative([r if isinstance(r, Recording) else Recording(
        r.name, np.arange(2.0), np.arange(2.0)[:, None] * np.ones(robot.dof) * r.moved,
        np.ones((2, robot.dof)) * r.torque) for r in read], True)
    return [r if isinstance(r, Source) else Source.held(condition(r, conditioning)) for r in read]
