"""The compiled-program cache on a shared machine (issue 10): a planted binary never runs.

The attack: dyngen caches the model library and the extractor driver under predictable names.
Whoever can write the cache folder can plant a program there that the next dyngen run loads or
executes. A planted shared library below has a constructor that creates a marker file the
moment it is loaded, so "not used" is observed, not assumed.
"""

from __future__ import annotations

import os
import stat
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from dyngen import cache
from dyngen.errors import InputError
from dyngen.generate import generate
from dyngen.runtime import load

TINY = Path(__file__).parent / "hostile" / "tiny.yaml"
PLANT = """
#include <stdio.h>
__attribute__((constructor)) static void planted(void) { FILE *f = fopen("{marker}", "w"); if (f) fclose(f); }
void tiny_gravity(const double *q, const double *s, double *g) { (void)q; (void)s; g[0] = 42; g[1] = 42; }
"""


def planted_library(path: Path, marker: Path) -> None:
    source = path.with_suffix(".c")
    source.write_text(PLANT.replace("{marker}", str(marker)))
    subprocess.run(["cc", "-shared", "-fPIC", str(source), "-o", str(path)], check=True)
    source.unlink()


@pytest.fixture(scope="module")
def model_folder(tmp_path_factory):
    return generate(TINY, tmp_path_factory.mktemp("gen")).folder


def test_a_library_changed_after_it_was_built_is_rebuilt_not_loaded(model_folder, tmp_path):
    root = tmp_path / "cache"
    first = load(model_folder, cache_dir=root)
    (library,) = (root / "libraries").glob("*.so")
    marker = tmp_path / "planted-ran"
    os.unlink(library)
    planted_library(library, marker)  # same name, other content (the recorded hash no longer matches)
    again = load(model_folder, cache_dir=root)
    assert not marker.exists(), "the planted library was loaded"
    q, s = np.array([0.3, -0.2]), np.linspace(0.5, 1.5, 20)
    assert np.allclose(again("gravity", q, s), first("gravity", q, s)) and again("gravity", q, s)[0] != 42


def test_cache_in_a_folder_others_can_write_is_refused(model_folder, tmp_path):
    shared = tmp_path / "shared"
    shared.mkdir()
    os.chmod(shared, 0o777)  # like /tmp without its sticky bit
    with pytest.raises(InputError, match="writable by others"):
        load(model_folder, cache_dir=shared / "dyngen")


def test_cache_folder_that_is_a_symlink_is_refused(model_folder, tmp_path):
    target = tmp_path / "elsewhere"
    target.mkdir()
    (tmp_path / "dyngen").symlink_to(target)
    with pytest.raises(InputError, match="symbolic link"):
        load(model_folder, cache_dir=tmp_path / "dyngen")


@pytest.mark.skipif(os.geteuid() != 0, reason="needs root to create a folder as another user")
def test_cache_planted_by_another_user_is_refused_and_never_loaded(model_folder, tmp_path):
    """The reproduced attack: `nobody` creates the cache folders first and plants a library under
    every name dyngen might use; root runs dyngen next."""
    os.chmod(tmp_path, 0o755)
    root = tmp_path / "dyngen"
    libraries = root / "libraries"
    libraries.mkdir(parents=True)
    marker = tmp_path / "planted-ran"
    for name in ("libtiny-double-0000000000000000.so",):
        planted_library(libraries / name, marker)
    for path in (root, libraries, *libraries.iterdir()):
        os.chown(path, 65534, 65534)  # nobody
    with pytest.raises(InputError, match="belongs to user id 65534"):
        load(model_folder, cache_dir=root)
    assert not marker.exists()


def test_cache_folders_are_private(model_folder, tmp_path):
    root = tmp_path / "dyngen"
    root.mkdir(mode=0o777)
    os.chmod(root, 0o777)  # ours but too open: tightened, not refused
    load(model_folder, cache_dir=root)
    for path in (root, root / "libraries"):
        assert stat.S_IMODE(os.stat(path).st_mode) == 0o700


def test_default_cache_is_per_user_and_not_in_the_temporary_directory(tmp_path):
    env = {k: v for k, v in os.environ.items() if k != cache.ENVIRONMENT}
    env["HOME"] = str(tmp_path / "home")
    env["XDG_CACHE_HOME"] = str(tmp_path / "home" / ".cache")
    code = "from dyngen import cache; print(cache.folder('drivers'))"
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True).stdout
    folder = Path(out.strip())
    assert folder.is_relative_to(tmp_path / "home")
    assert stat.S_IMODE(os.stat(folder).st_mode) == 0o700 and stat.S_IMODE(os.stat(folder.parent).st_mode) == 0o700


def test_the_command_reports_an_unsafe_cache_in_one_line(tmp_path):
    shared = tmp_path / "shared"
    shared.mkdir()
    os.chmod(shared, 0o777)
    rows = "".join(f"{0.01 * k:.2f},{0.1 * k:.2f},{0.05 * k:.3f},0.1,0.2\n" for k in range(100))
    (tmp_path / "run.csv").write_text("t,q1,q2,tau1,tau2\n" + rows)
    env = dict(os.environ, DYNGEN_CACHE_DIR=str(shared / "dyngen"))
    result = subprocess.run([sys.executable, "-m", "dyngen.cli", "identify", str(TINY), "--data", "run.csv", "-q"],
                            cwd=tmp_path, env=env, capture_output=True, text=True)
    assert result.returncode != 0 and len(result.stderr.strip().splitlines()) == 1, result.stderr
    assert "writable by others" in result.stderr and str(shared) in result.stderr
