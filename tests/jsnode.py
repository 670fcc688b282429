"""Running the simulator's JavaScript under node, for the parity tests, and Chromium, for the
page and browser tests.

`require_tool` skips a test when a tool is missing on a developer's machine,
and fails it when the environment variable CI is "true": in CI nothing that
checks the simulator may silently skip.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from renderer import Scene, jsgen

DRIVERS = Path(__file__).with_name("js")
#: Where tests leave artifacts (tables, screenshots) for the closing notes.
ARTIFACTS = Path(os.environ.get("SYMRENDER_ARTIFACTS", Path(__file__).parents[1] / "test-artifacts"))


def in_ci():
    return os.environ.get("CI", "").lower() == "true"


#: node's V8 runs no background tasks.  Without this, node 20 deadlocked now and then on exit
#: (about one run in 80 with another process busy): the main thread, draining V8's tasks,
#: waited for a background compile that itself waited for a garbage collection only the main
#: thread runs.
NODE_FLAGS = ("--single-threaded",)


#: Debian's Chromium for the page and browser tests: its headless shell (package
#: chromium-headless-shell: the browser's engine, of the same version, without its window and
#: compositor; `make audit` took 116 s twice with it against 124 and 134 s with the browser, alternated
#: on 2 cores), or the browser where the shell is not installed.
CHROMIUM = next((p for p in ("/usr/bin/chromium-headless-shell", "/usr/bin/chromium") if Path(p).exists()),
                "/usr/bin/chromium-headless-shell")
# Flags for a machine with no network: without the background-networking ones Chromium keeps
# trying to reach Google's hosts.
CHROMIUM_ARGS = ("--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                 "--disable-background-networking", "--disable-component-update", "--disable-sync")


def chromium(why):
    """Yield `CHROMIUM` launched headless by playwright (a module fixture's body); skip (locally) or
    fail (CI=true) if it or playwright is missing, ``why`` naming the test that needs it."""
    require_tool(CHROMIUM, why + " (apt-get install chromium-headless-shell)")
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        if in_ci():
            pytest.fail("playwright is not installed (CI=true: this test may not skip)")
        pytest.skip("playwright is not installed")
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, headless=True, args=list(CHROMIUM_ARGS))
        yield browser
        browser.close()


def node_command(why):
    """[node, *NODE_FLAGS], to which a test appends its script and arguments (`require_tool`)."""
    return [require_tool("node", why), *NODE_FLAGS]


def require_tool(path_or_name, why):
    """Return the tool's path; skip (locally) or fail (CI=true) if it is missing."""
    found = shutil.which(path_or_name) or (Path(path_or_name).exists() and str(path_or_name))
    if found:
        return found
    message = f"{path_or_name} not found: {why}"
    if in_ci():
        pytest.fail(message + " (CI=true: this test may not skip)")
    pytest.skip(message)


def write_modules(directory, transform=None):
    """Write the ES modules to ``directory``; ``transform(name, text)`` may alter one (wrong variants)."""
    paths = jsgen.write_modules(directory)
    if transform is not None:
        for name, path in paths.items():
            text = path.read_text(encoding="utf-8")
            new = transform(name, text)
            if new != text:
                path.write_text(new, encoding="utf-8")
    return Path(directory)


def scene_json(scene: Scene, base: Scene = Scene()):
    """The fields of ``scene`` that differ from ``base``, as the driver expects them."""
    out = {}
    for name in scene.__dataclass_fields__:
        value = getattr(scene, name)
        if value == getattr(base, name):
            continue
        if name == "lights":
            value = [{"position": list(l.position), "color": list(l.color)} for l in value]
        elif isinstance(value, tuple):
            value = list(value)
        out[name] = value
    return out


def run_render_cases(module_dir, cases, out_dir):
    """Render ``cases`` (dicts: id, scene: Scene, width, height, gradient, zoom[, numeric]) in node.

    Returns {id: ms} and leaves the frames in ``out_dir`` (read them with `read_frame`).
    """
    node = node_command("the JS parity tests run the renderer core under node")
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    payload = [dict(c, scene=scene_json(c["scene"])) for c in cases]
    cases_path = out_dir / "cases.json"
    cases_path.write_text(json.dumps(payload), encoding="utf-8")
    proc = subprocess.run([*node, str(DRIVERS / "parity_driver.mjs"), str(module_dir), str(cases_path),
                           str(out_dir)], capture_output=True, text=True, timeout=600)
    if proc.returncode != 0:
        raise RuntimeError(f"node parity driver failed:\n{proc.stderr}")
    return {rec["id"]: rec["ms"] for rec in map(json.loads, proc.stdout.splitlines())}


def read_frame(out_dir, prefix, width, height):
    """(image (H, W, 3), grad (H, W, 2), chamber (H, W) uint8, kink (H, W) bool,
    uv (H, W, 2)) of a frame written by node; grad and uv are 0 off sphere A."""
    out_dir = Path(out_dir)
    read = lambda name, dtype: np.fromfile(out_dir / f"{prefix}.{name}", dtype=dtype)  # noqa: E731
    image = read("image.f64", "<f8").reshape(height, width, 3)
    grad = read("grad.f64", "<f8").reshape(height, width, 2)
    chamber = read("chamber.u8", np.uint8).reshape(height, width)
    kink = read("kink.u8", np.uint8).reshape(height, width).astype(bool)
    uv = read("uv.f64", "<f8").reshape(height, width, 2)
    return image, grad, chamber, kink, uv
