"""Bad URDFs: one line `dyngen: error: FILE: ELEMENT: what`, a non-zero exit, nothing written."""

from __future__ import annotations

import subprocess
import sys

import pytest

LINK = '<link name="{name}"><inertial><origin xyz="0 0 0.1"/><mass value="{mass}"/>' \
       '<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>{extra}</link>'
JOINT = '<joint name="{name}" type="{type}"><origin xyz="0 0 0.2" rpy="{rpy}"/><parent link="{parent}"/>' \
        '<child link="{child}"/><axis xyz="0 0 1"/>{extra}</joint>'


def arm(links=None, joints=None, prolog=""):
    links = links or [LINK.format(name=f"l{i}", mass=1, extra="") for i in range(4)]
    joints = joints or [JOINT.format(name=f"j{i}", type="revolute", rpy="1.5708 0 0", parent=f"l{i - 1}", child=f"l{i}",
                                     extra="") for i in range(1, 4)]
    return f'{prolog}<robot name="arm">{"".join(links)}{"".join(joints)}</robot>'


def _links(**changes):
    return [changes.get(f"l{i}", LINK.format(name=f"l{i}", mass=1, extra="")) for i in range(4)]


CASES = {
    "missing_inertial": (arm(links=_links(l2='<link name="l2"/>')), 'link "l2".inertial: missing'),
    "massless_mid_chain": (arm(links=_links(l2=LINK.format(name="l2", mass=0, extra=""))), 'link "l2".inertial'),
    "nan": (arm(links=_links(l1=LINK.format(name="l1", mass="nan", extra=""))), 'link "l1".inertial.mass'),
    "mimic": (arm(joints=[JOINT.format(name=f"j{i}", type="revolute", rpy="0 0 0", parent=f"l{i - 1}", child=f"l{i}",
                                       extra='<mimic joint="j1"/>' if i == 2 else "") for i in range(1, 4)]),
              'joint "j2": a mimic joint'),
    "branching": (arm(links=_links() + [LINK.format(name="l4", mass=1, extra="")],
                      joints=[JOINT.format(name=f"j{i}", type="revolute", rpy="0 0 0", parent=f"l{p}", child=f"l{i}",
                                           extra="") for i, p in ((1, 0), (2, 1), (3, 2), (4, 2))]),
                  "tip_link: the tree has 2 leaves (l3, l4)"),
    "mesh_outside": (arm(links=_links(l1=LINK.format(name="l1", mass=1, extra='<visual><geometry><mesh filename='
                                                     '"../../secret.stl"/></geometry></visual>'))),
                     'link "l1".mesh'),
    "xml_bomb": (arm(prolog='<?xml version="1.0"?><!DOCTYPE robot [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;'
                     '&a;&a;&a;&a;&a;&a;"><!ENTITY c "&b;&b;&b;&b;&b;&b;&b;&b;&b;&b;">]>').replace(
                         'name="arm"', 'name="&c;"'), "declares a DTD"),
    "external_entity": (arm(prolog='<?xml version="1.0"?><!DOCTYPE robot [<!ENTITY x SYSTEM "file:///etc/passwd">]>')
                        .replace('name="arm"', 'name="&x;"'), "declares a DTD"),
    "floating": (arm(joints=[JOINT.format(name=f"j{i}", type="floating" if i == 2 else "revolute", rpy="0 0 0",
                                          parent=f"l{i - 1}", child=f"l{i}", extra="") for i in range(1, 4)]),
                 'joint "j2": a floating joint'),
    "closed_loop": (arm(joints=[JOINT.format(name=f"j{i}", type="revolute", rpy="0 0 0", parent=f"l{p}", child=f"l{c}",
                                             extra="") for i, p, c in ((1, 0, 1), (2, 1, 2), (3, 2, 3), (4, 1, 3))]),
                    'joint "j4": link "l3" has a second parent'),
    "zero_axis": (arm().replace('<axis xyz="0 0 1"/>', '<axis xyz="0 0 0"/>', 1), 'joint "j1".axis: the axis has zero'),
    "xacro_inside": (arm(links=_links(l1=LINK.format(name="l1", mass="${2*m}", extra=""))), "a xacro file is a program"),
    "xacro_macro": (arm().replace('<robot name="arm">', '<robot name="arm" xmlns:xacro="http://www.ros.org/wiki/xacro">'
                                  '<xacro:include filename="other.xacro"/>'), "xacro:include: a xacro file is a program"),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_bad_urdf_is_one_line_and_writes_nothing(case, tmp_path):
    text, expected = CASES[case]
    path = tmp_path / f"{case}.urdf"
    path.write_text(text)
    out = tmp_path / "out"
    run = subprocess.run([sys.executable, "-m", "dyngen", "generate", str(path), "-o", str(out), "-q"],
                         capture_output=True, text=True, timeout=120)
    assert run.returncode != 0
    lines = run.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"dyngen: error: {case}.urdf: "), run.stderr
    assert expected in lines[0], lines[0]
    assert not out.exists()


def test_a_xacro_file_is_not_run(tmp_path):
    """Refused by its name before it is read: expanding it would evaluate its Python expressions."""
    (tmp_path / "arm.urdf.xacro").write_text(arm().replace('name="arm"', 'name="${__import__(\'os\').system(\'touch '
                                                           + str(tmp_path / "ran") + '\')}"'))
    run = subprocess.run([sys.executable, "-m", "dyngen", "generate", str(tmp_path / "arm.urdf.xacro"), "-o",
                          str(tmp_path / "out"), "-q"], capture_output=True, text=True, timeout=120)
    assert run.returncode != 0 and not (tmp_path / "out").exists() and not (tmp_path / "ran").exists()
    assert run.stderr.strip().startswith("dyngen: error: arm.urdf.xacro: a xacro file is a program"), run.stderr


def test_the_good_arm_of_these_cases_generates(tmp_path):
    """The template itself is fine: the failures above are the changes' doing."""
    path = tmp_path / "good.urdf"
    path.write_text(arm())
    run = subprocess.run([sys.executable, "-m", "dyngen", "generate", str(path), "-o", str(tmp_path / "out"), "-q"],
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    assert (tmp_path / "out" / "arm" / "arm.h").exists()
