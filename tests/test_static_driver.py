"""The extractor driver is one static program (generator/dyngen/extraction/driver_cpp/): its protocol part is
current with the schema, it names no arm, and `dyngen extract` writes it as a standalone copy
with the arm's build line; its behaviour is tested in test_extraction.py and test_protocol.py."""

from __future__ import annotations

from dyngen.extraction import driver, protocol


def test_the_checked_in_protocol_header_is_rendered_from_the_schema():
    assert protocol.HEADER.read_text() == protocol.cpp_header(), \
        "extraction/driver_cpp/protocol.hpp is stale: run `python3 -m dyngen.extraction.protocol`"


def test_the_static_driver_names_no_arm():
    for name in (*driver.CORE_SOURCES, "robot.c"):
        text = (driver.DRIVER / name).read_text()
        assert "{{" not in text and "lwr_" not in text and "LWR_" not in text, name


def test_the_standalone_copy_has_every_source_and_the_arm_build_line(tmp_path):
    files = driver.standalone_files(tmp_path / "ur5")
    assert {"driver.cpp", "protocol.hpp", "robot.h", "robot.c", "BUILD.txt"} <= set(files)
    assert "ur5_kinds.h" in files["BUILD.txt"] and "-lnlopt" in files["BUILD.txt"]
