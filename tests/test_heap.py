"""renderer.heap: a warm render faults in no fresh page, and changes no bit.

Each case runs in its own Python process: the allocator settings are
process-wide and are applied once, on the first render.
"""

from __future__ import annotations

import json
import os
import platform
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

# Renders a warm 256^2 frame on one thread, counts the minor page faults of
# the next five, and hashes the image.
_PROBE = r"""
import hashlib, json, resource, sys
sys.path.insert(0, sys.argv[1])
from renderer import Scene, render
from renderer.heap import keep_heap
scene = Scene()
for _ in range(3):
    frame = render(scene, 256, 256, workers=1)
before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
for _ in range(5):
    frame = render(scene, 256, 256, workers=1)
faults = (resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before) / 5
print(json.dumps({"applied": keep_heap(), "faults": faults,
                  "sha": hashlib.sha256(frame.image.tobytes()).hexdigest()}))
"""


def _probe(keep):
    env = dict(os.environ)
    env.pop("SYMRENDER_KEEP_HEAP", None)
    if not keep:
        env["SYMRENDER_KEEP_HEAP"] = "0"
    out = subprocess.run([sys.executable, "-c", _PROBE, str(ROOT)], env=env, check=True,
                         capture_output=True, text=True, timeout=300)
    return json.loads(out.stdout.strip().splitlines()[-1])


GLIBC = platform.system() == "Linux" and platform.libc_ver()[0] == "glibc"


@pytest.fixture(scope="module")
def probes():
    return {"kept": _probe(True), "left alone": _probe(False)}


def test_settings_apply_on_glibc_only_and_not_when_disabled(probes):
    assert probes["kept"]["applied"] is GLIBC
    assert probes["left alone"]["applied"] is False


def test_warm_render_faults_in_no_fresh_pages(probes):
    """The point of the settings: a warm frame reuses the heap's pages.

    The wrong variant (the allocator left alone) is checked too, so this test
    can fail: there every 256^2 frame faults in thousands of pages (about
    7,400 here), the temporaries' memory handed back and taken again.
    """
    kept, alone = probes["kept"]["faults"], probes["left alone"]["faults"]
    if GLIBC:
        assert kept < 100, f"{kept:.0f} page faults per warm frame with the heap kept"
        assert alone > 10 * max(kept, 100), (
            f"the allocator left alone faults only {alone:.0f} pages per frame: "
            "the check would not tell the settings apart")
    else:
        assert not probes["kept"]["applied"]


def test_the_settings_change_no_bit(probes):
    assert probes["kept"]["sha"] == probes["left alone"]["sha"]


def test_keep_heap_answers_the_same_on_every_call():
    from renderer.heap import keep_heap
    first = keep_heap()
    assert keep_heap() is first
