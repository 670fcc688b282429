"""renderer.backends and render(backend=...): the array kernel beside the numba kernel.

* Dr.Jit against numba on the default scene at 256 x 256, exact and central:
  the same chambers and crease flags, |dI| within the parity tolerance (the
  parity matrix of tests/test_parity.py checks every backend against the
  scalar reference on small frames; this is the frame the benchmark times).
* The choice of backend: validated like every keyword; "drjit" where
  Dr.Jit's LLVM backend is missing is refused with what is missing, and
  "auto" falls back to numba (checked in a process without libLLVM).
* The namespaces' building blocks: the pixel grid's order and the
  repeated-squaring power give the numba kernel's values.
"""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest

import sympy as sp

from renderer import PointLight, Scene, arraykernel, backends, codegen, kernel, render, validate
from renderer import formulas as F
from tests.test_parity import IMAGE_TOL, LIGHT_2, grad_tolerance, require_backend

ARRAY_BACKENDS = ("numpy", "drjit")


@pytest.fixture(scope="module")
def numba_frames():
    return {g: render(Scene(), 256, 256, gradient=g) for g in ("exact", "central")}


def frame_differences(a, b):
    """(max |dI|, chamber pixels that differ, crease pixels that differ, max |d grad|)."""
    return (float(np.abs(a.image - b.image).max()), int(np.count_nonzero(a.chamber != b.chamber)),
            int(np.count_nonzero(a.kink != b.kink)), float(np.abs(a.grad - b.grad).max()))


@pytest.mark.parametrize("gradient", ["exact", "central"])
def test_drjit_renders_the_numba_frame_at_256(numba_frames, gradient):
    require_backend("drjit")
    frame = render(Scene(), 256, 256, gradient=gradient, backend="drjit")
    d_image, chambers, creases, d_grad = frame_differences(frame, numba_frames[gradient])
    assert (chambers, creases) == (0, 0)
    assert d_image <= IMAGE_TOL
    # The parity tests' gradient tolerance (the central quotient divides the few-ulp differences
    # of the sines by 2 eps).
    grad = numba_frames[gradient].grad
    assert np.all(np.abs(frame.grad - grad) <= grad_tolerance(Scene(), gradient, grad))


def test_the_frame_comparison_rejects_another_scene(numba_frames):
    frame = render(Scene(beta=0.51), 256, 256, gradient="exact", backend="numpy")
    assert frame_differences(frame, numba_frames["exact"])[0] > IMAGE_TOL
    frame = render(Scene(center_b=(0.5, 0.45, 1.3)), 256, 256, gradient="exact", backend="numpy")
    assert frame_differences(frame, numba_frames["exact"])[1] > 0


@pytest.mark.parametrize("backend", ARRAY_BACKENDS)
def test_array_backends_return_the_frames_types_and_shapes(backend):
    require_backend(backend)
    frame = render(Scene(), 7, 5, backend=backend)
    assert (frame.image.shape, frame.image.dtype, frame.chamber.shape, frame.chamber.dtype) == \
        ((5, 7, 3), np.float64, (5, 7), np.uint8)
    assert (frame.kink.dtype, frame.grad.shape, frame.grad.dtype) == (np.bool_, (5, 7, 2), np.float64)
    bare = render(Scene(), 7, 5, backend=backend, kink=False, grad=False)
    assert bare.kink is None and bare.grad is None
    assert np.array_equal(bare.image, frame.image)


@pytest.mark.parametrize("backend", ARRAY_BACKENDS)
def test_each_namespace_has_every_function_a_field_may_call(backend):
    """The array code calls ``xp.<name>`` for each of `formulas.ELEMENTARY` (a reader's field may use any):
    each name the printer writes is the namespace's function of that name."""
    require_backend(backend)
    xp, x = backends.namespace(backend), sp.Symbol("x")
    for f in F.ELEMENTARY:
        name = codegen._array(f(x)).removeprefix("xp.").removesuffix("(x)")
        assert getattr(xp, name, None) is not None, (backend, f, name)
    with pytest.raises(AssertionError):                      # the check sees a missing one
        assert getattr(xp, codegen._array(sp.erf(x)).removeprefix("xp.").removesuffix("(x)"), None) is not None
    assert [codegen._array(c) for c in (sp.pi, sp.E)] == ["math.pi", "math.e"]    # constants: math's floats


@pytest.mark.parametrize("backend", ARRAY_BACKENDS)
def test_a_frame_taller_than_one_block_is_the_blocks_in_order(backend, monkeypatch):
    """Blocks of rows (`render.ARRAY_BLOCK_PIXELS`) put together: the frame of one block."""
    require_backend(backend)
    whole = render(Scene(), 24, 20, backend=backend)
    # 7 blocks, the last of 2 rows
    monkeypatch.setitem(sys.modules["renderer.render"].ARRAY_BLOCK_PIXELS, backend, 24 * 3)
    parts = render(Scene(), 24, 20, backend=backend)
    for name in ("image", "chamber", "kink", "grad"):
        assert np.array_equal(getattr(parts, name), getattr(whole, name)), name


@pytest.mark.parametrize("value, error", [("cuda", ValueError), ("Numba", ValueError), (None, TypeError),
                                          (1, TypeError)])
def test_backend_is_validated(value, error):
    with pytest.raises(error, match="^backend"):
        render(Scene(), 4, 4, backend=value)


def test_drjit_without_llvm_is_refused_with_what_is_missing(monkeypatch):
    monkeypatch.setattr(backends, "drjit_llvm", lambda: None)
    monkeypatch.setattr(backends, "llvm_library", lambda: None)
    with pytest.raises(validate.InvalidValue, match="^backend") as info:
        render(Scene(), 4, 4, backend="drjit")
    assert "DRJIT_LIBLLVM_PATH" in str(info.value) and "libllvm19" in str(info.value)
    assert backends.resolve("auto") == "numba"


def test_without_the_system_llvm_auto_renders_with_numba_and_drjit_is_refused():
    """In a fresh process with DRJIT_LIBLLVM_PATH pointing nowhere (a machine without libLLVM)."""
    code = ("from renderer import Scene, render, backends, validate\n"
            "import numpy as np\n"
            "assert backends.drjit_llvm() is None and backends.resolve('auto') == 'numba'\n"
            "a, b = render(Scene(), 9, 7, backend='auto'), render(Scene(), 9, 7)\n"
            "assert np.array_equal(a.image, b.image)\n"
            "try:\n    render(Scene(), 9, 7, backend='drjit')\nexcept validate.InvalidValue as e:\n"
            "    print('refused:', e)\n")
    env = {**os.environ, "DRJIT_LIBLLVM_PATH": "/nonexistent"}
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=300)
    assert result.returncode == 0, result.stderr
    assert result.stdout.startswith("refused: backend") and "/nonexistent" in result.stdout


def test_discovery_takes_the_newest_llvm_that_is_new_enough(tmp_path, monkeypatch):
    """LLVM 15 and 16 abort the process on Dr.Jit's atan2: an older library is never chosen,
    however it is spelled, and a newer one is chosen over an older usable one."""
    monkeypatch.delenv("DRJIT_LIBLLVM_PATH", raising=False)
    monkeypatch.setattr(backends, "LIBRARY_PATTERNS", (str(tmp_path / "*" / "libLLVM*.so*"),))
    old = backends.MIN_LLVM_VERSION - 1
    for name in (f"a/libLLVM-{old}.so", f"b/libLLVM.so.{old}.0", f"c/libLLVM-{old}.so.1"):
        (tmp_path / name).parent.mkdir(exist_ok=True)
        (tmp_path / name).write_bytes(b"")
    assert backends.llvm_library() is None
    for version in (backends.MIN_LLVM_VERSION, backends.MIN_LLVM_VERSION + 2):
        (tmp_path / "d" / f"libLLVM-{version}.so.1").parent.mkdir(exist_ok=True)
        (tmp_path / "d" / f"libLLVM-{version}.so.1").write_bytes(b"")
    assert backends.llvm_library() == str(tmp_path / "d" / f"libLLVM-{backends.MIN_LLVM_VERSION + 2}.so.1")


def test_a_loaded_llvm_older_than_the_minimum_is_refused(tmp_path, monkeypatch):
    """DRJIT_LIBLLVM_PATH may name any library: the version Dr.Jit loaded (in `backends.probe`'s
    child process, here a stand-in) decides, and the refusal names the variable, the library
    and the minimum."""
    path = tmp_path / "libLLVM-99.so"
    path.write_bytes(b"")
    monkeypatch.setenv("DRJIT_LIBLLVM_PATH", str(path))
    monkeypatch.setattr(backends, "probe", lambda p: (backends.MIN_LLVM_VERSION - 1, None))
    assert backends._drjit_llvm.__wrapped__() is None
    monkeypatch.setattr(backends, "drjit_llvm", lambda: None)
    assert (f"DRJIT_LIBLLVM_PATH={str(path)!r} is older than LLVM {backends.MIN_LLVM_VERSION} (it is LLVM "
            f"{backends.MIN_LLVM_VERSION - 1})") in backends.missing("drjit")


#: A libLLVM cut short (its first 100,000 bytes): loading it kills the process with SIGBUS.
TRUNCATED = 100_000


@pytest.mark.parametrize("how", ["truncated", "not a library"])
def test_a_library_that_cannot_load_is_refused_in_one_line_and_auto_renders_with_numba(tmp_path, how):
    """DRJIT_LIBLLVM_PATH naming a truncated libLLVM (before: the process died of SIGBUS, no
    message, under ``auto`` too) or a file that is no library (before: Dr.Jit's two lines on
    stderr): ``--backend drjit`` is one line naming the variable and the path, exit 2;
    ``--backend auto`` renders the numba frame after one line saying why."""
    library = backends.llvm_library() if how == "truncated" else None
    if how == "truncated" and (library is None or not os.path.isfile(library)):
        require_backend("drjit")
    path = tmp_path / "libLLVM-20.so"
    path.write_bytes(open(library, "rb").read(TRUNCATED) if library else b"not an ELF file\n" * 100)
    env = {**os.environ, "DRJIT_LIBLLVM_PATH": str(path)}
    argv = [sys.executable, "-m", "renderer.cli", "render", "--size", "8x8", "-o"]
    refused = subprocess.run(argv + [str(tmp_path / "a.png"), "--backend", "drjit"], capture_output=True,
                             text=True, env=env, timeout=300)
    assert (refused.returncode, len(refused.stderr.splitlines())) == (2, 1), refused
    assert f"DRJIT_LIBLLVM_PATH={str(path)!r}" in refused.stderr and not (tmp_path / "a.png").exists()
    if how == "truncated":
        assert "SIGBUS" in refused.stderr
    auto = subprocess.run(argv + [str(tmp_path / "b.png"), "--backend", "auto"], capture_output=True, text=True,
                          env=env, timeout=300)
    assert auto.returncode == 0, auto
    assert auto.stderr.splitlines() == [auto.stderr.strip()] and "renders with numba" in auto.stderr, auto.stderr
    numba = subprocess.run(argv + [str(tmp_path / "c.png")], capture_output=True, text=True, env=env, timeout=300)
    assert numba.returncode == 0, numba.stderr
    assert (tmp_path / "b.png").read_bytes() == (tmp_path / "c.png").read_bytes()


def test_the_probe_reads_the_childs_death_and_words(monkeypatch):
    """`backends.probe` in its three outcomes, from a stand-in child: a version, Dr.Jit's words
    (one line, not printed), a death by signal (named)."""
    said = "import sys; print('jit_find_library(): Unable to load', file=sys.stderr); print('x', file=sys.stderr)"
    for code, want in [("print(19)", (19, None)),
                       (said, (None, "Dr.Jit could not load it: jit_find_library(): Unable to load; x")),
                       ("import os, signal; os.kill(os.getpid(), signal.SIGBUS)",
                        (None, "loading it killed the child process that tried (SIGBUS)"))]:
        monkeypatch.setattr(backends, "_PROBE", code)
        assert backends.probe.__wrapped__("/any/libLLVM.so") == want


THREADED = """
import sys, threading
import numpy as np
from renderer import Scene, render
jobs = [(Scene(), 32, 24), (Scene(height_field="ridges"), 40, 16), (Scene(beta=0.8), 16, 32)]
threads, repeats = int(sys.argv[1]), int(sys.argv[2])
frames, start = {}, threading.Barrier(threads)
def work(i):
    start.wait()
    for r in range(repeats):
        k = (i + r) % len(jobs)
        frames[i, r] = k, render(*jobs[k], backend="drjit").image
workers = [threading.Thread(target=work, args=(i,)) for i in range(threads)]
for t in workers:
    t.start()
for t in workers:
    t.join()
alone = [render(*job, backend="drjit").image for job in jobs]
print(len(frames), sum(not np.array_equal(image, alone[k]) for k, image in frames.values()))
"""


@pytest.mark.parametrize("threads", [4])
def test_drjit_renders_from_several_threads_at_once_as_from_one(threads):
    """Four threads rendering on Dr.Jit at once, 30 frames each: every frame is the one rendered
    alone, nothing on stderr, within 120 s (3 s here).  Before `backends.DRJIT_LOCK` the
    process aborted ("jit_var(...): unknown variable!"), a replay raised ("Kernel input
    variable ... not allocated"), Dr.Jit printed "The frozen function has been recorded 11
    times", or the threads spun for minutes.  In a child process: the failure can kill it."""
    require_backend("drjit")
    repeats = 30
    try:
        child = subprocess.run([sys.executable, "-c", THREADED, str(threads), str(repeats)], capture_output=True,
                               text=True, timeout=120)
    except subprocess.TimeoutExpired:
        pytest.fail(f"{threads} threads rendering on Dr.Jit did not finish in 120 s")
    assert (child.returncode, child.stderr) == (0, ""), child.stderr[-2000:]
    assert child.stdout.split() == [str(threads * repeats), "0"]


def test_auto_is_drjit_where_it_is_available():
    require_backend("drjit")
    assert backends.resolve("auto") == "drjit"


@pytest.mark.parametrize("backend", ARRAY_BACKENDS)
def test_the_grid_is_row_major(backend):
    require_backend(backend)
    xp = backends.namespace(backend)
    x, y = xp.grid(np.array([1.0, 2.0, 3.0]), np.array([10.0, 20.0]))
    got = xp.numpy([([x], np.float64), ([y], np.float64)])
    assert got[0].tolist() == [1.0, 2.0, 3.0] * 2 and got[1].tolist() == [10.0] * 3 + [20.0] * 3


@pytest.mark.parametrize("n", [0, 1, 2, 3, 7, 32, 33, 100])
def test_int_power_is_the_numba_kernels(n):
    """The same multiplications in the same order: bit for bit the kernel's (interpreted)."""
    base = np.random.default_rng(n).uniform(0.0, 1.0, 64)
    got = np.broadcast_to(arraykernel.int_power(base, n), base.shape)
    assert np.array_equal(got, [kernel.int_power.py_func(float(b), n) for b in base])


def extreme_cases():
    """(scene name, gradient, backend): the accepted extremes of tests/test_interpreted.py, numpy
    with every pipeline, Dr.Jit (a compiled kernel per scene) with the exact one."""
    from tests.test_interpreted import SCENES
    return [(name, g, b) for name in SCENES for g in ("exact", "central", "footprint")
            for b in ARRAY_BACKENDS if b == "numpy" or g == "exact"]


@pytest.mark.parametrize("name, gradient, backend", extreme_cases())
def test_array_backends_render_the_extreme_scenes_as_numba_does(name, gradient, backend):
    """Lights within 1e-170 of a point, the pole on a pixel, the limits of every field.  At the
    least eps (1e-12) a central quotient turns the libraries' few-ulp differences of sin into
    O(1) gradients (the U-curve's roundoff floor): there only chambers and creases are compared."""
    from tests.test_interpreted import SCENES
    require_backend(backend)
    scene, width, height = SCENES[name]
    d_image, chambers, creases, _ = frame_differences(render(scene, width, height, gradient=gradient,
                                                             backend=backend),
                                                      render(scene, width, height, gradient=gradient))
    assert (chambers, creases) == (0, 0)
    if gradient == "exact" or scene.eps >= 1e-6:
        assert d_image <= IMAGE_TOL


def test_the_command_line_renders_with_drjit_or_says_what_is_missing(tmp_path):
    """``symrender render --backend``: where the LLVM library is missing, one line and exit 2
    (an input error) and no file; with ``auto`` there, the numba frame."""
    env = {**os.environ, "DRJIT_LIBLLVM_PATH": "/nonexistent"}
    argv = [sys.executable, "-m", "renderer.cli", "render", "--size", "16x12", "-o"]
    refused = subprocess.run(argv + [str(tmp_path / "a.png"), "--backend", "drjit"], capture_output=True,
                             text=True, env=env, timeout=300)
    assert (refused.returncode, len(refused.stderr.splitlines())) == (2, 1), refused.stderr
    assert "backend" in refused.stderr and not (tmp_path / "a.png").exists()
    auto = subprocess.run(argv + [str(tmp_path / "b.png"), "--backend", "auto"], capture_output=True, text=True,
                          env=env, timeout=300)
    assert auto.returncode == 0 and (tmp_path / "b.png").exists(), auto.stderr


def test_frozen_programs_past_the_cache_limit_replay_only_their_own_configuration(monkeypatch):
    """More configurations than `backends.FROZEN_CONFIGURATIONS` (set to 3 here), then a frame in
    blocks of two shapes: each block is its own configuration's frame (Dr.Jit's own LRU of
    recordings, ``drjit.freeze(limit=...)``, replayed a 3-row recording for the 2-row block)."""
    require_backend("drjit")
    monkeypatch.setattr(backends, "FROZEN_CONFIGURATIONS", 3)
    xp = backends.namespace("drjit")
    for shininess in (10.0, 20.0, 30.0, 40.0, 50.0):      # five structures (int_power's multiplications)
        render(Scene(shininess=shininess), 24, 20, backend="drjit")
    assert len(xp._frozen) == 3
    monkeypatch.setitem(sys.modules["renderer.render"].ARRAY_BLOCK_PIXELS, "drjit", 24 * 3)
    parts = render(Scene(shininess=20.0), 24, 20, backend="drjit")
    reference = render(Scene(shininess=20.0), 24, 20)
    assert np.array_equal(parts.chamber, reference.chamber)
    assert np.abs(parts.image - reference.image).max() < 1e-12


# --- One compiled kernel per structure ------------------------------------------------------------
#: Pairs of scenes that differ in one branch of `arraykernel.program` (the first rendered
#: first), by the part of `arraykernel.structure` that tells them apart.
_OUT, _INSIDE_B, _ON_A = (4.0, 5.0, 6.0), (0.5, 0.5, 1.3), (0.0, 0.0, 1.0)
STRUCTURE_PAIRS = {
    "height field": (Scene(), Scene(height_field="sine")),
    "bump": (Scene(), Scene(bump="chart")),
    "model": (Scene(), Scene(model="phong")),
    "sphere B": (Scene(lights=()), Scene(lights=(), sphere_b=False)),   # with lights, their cases differ too
    "floor": (Scene(), Scene(floor=False)),
    "beta = 0": (Scene(beta=0.0), Scene(beta=0.35)),
    "shininess": (Scene(shininess=32.0), Scene(shininess=33.0)),
    "black light": (Scene(lights=(PointLight(_OUT, (0.0, 0.0, 0.0)),)), Scene(lights=(PointLight(_OUT, (1.0, 1.0, 1.0)),))),
    "light below the floor": (Scene(lights=(PointLight(_OUT, (1.0, 1.0, 1.0)),)),
                              Scene(lights=(PointLight((4.0, 5.0, -6.0), (1.0, 1.0, 1.0)),))),
    "light inside a sphere": (Scene(lights=(PointLight(_OUT, (1.0, 1.0, 1.0)),)),
                              Scene(lights=(PointLight(_INSIDE_B, (1.0, 1.0, 1.0)),))),
    "light on a sphere": (Scene(lights=(PointLight(_OUT, (1.0, 1.0, 1.0)),)),
                          Scene(lights=(PointLight(_ON_A, (1.0, 1.0, 1.0)),))),
}


def _replays_right(pair):
    """Render the pair's first scene, then its second, on Dr.Jit (grad=False, so that beta = 0
    skips the gradient): whether the second is the numba kernel's frame."""
    first, second = pair
    render(first, 24, 20, backend="drjit", grad=False)
    got, want = render(second, 24, 20, backend="drjit", grad=False), render(second, 24, 20, grad=False)
    return bool(np.array_equal(got.chamber, want.chamber) and np.abs(got.image - want.image).max() <= IMAGE_TOL)


@pytest.mark.parametrize("name", STRUCTURE_PAIRS)
def test_each_branch_of_the_array_program_has_a_kernel_of_its_own(name, monkeypatch):
    require_backend("drjit")
    monkeypatch.setattr(backends.namespace("drjit"), "_frozen", {})
    first, second = STRUCTURE_PAIRS[name]
    assert arraykernel.structure(first) != arraykernel.structure(second)
    assert _replays_right(STRUCTURE_PAIRS[name])


def test_scenes_that_differ_only_in_numbers_share_one_kernel(monkeypatch):
    """Every number of a scene is a value of the compiled kernel, not a constant: one frozen
    function renders them all, each as the numba kernel does."""
    require_backend("drjit")
    xp = backends.namespace("drjit")
    monkeypatch.setattr(xp, "_frozen", {})
    scenes = [Scene(), Scene(beta=0.2, k_u=5.0, k_v=3.0, shininess=32.0, ks=0.3, kd=0.6, ka=0.2, floor_tint=0.5,
                             center_b=(0.4, 0.6, 1.2), radius_b=0.3, radius_a=0.9, camera_z=3.5,
                             ambient=(0.1, 0.2, 0.3), albedo_a=(0.2, 0.3, 0.4), albedo_b=(0.5, 0.4, 0.3),
                             lights=(PointLight((3.0, 4.0, 5.0), (0.7, 0.8, 0.9)), LIGHT_2), eps=2e-3)]
    assert arraykernel.structure(scenes[0]) == arraykernel.structure(scenes[1])
    for gradient in ("exact", "central", "footprint"):
        for s in scenes:
            got, want = render(s, 24, 20, backend="drjit", gradient=gradient), render(s, 24, 20, gradient=gradient)
            assert np.array_equal(got.chamber, want.chamber) and np.abs(got.image - want.image).max() <= IMAGE_TOL
    assert len(xp._frozen) == 3                                  # one per gradient method


def _without(part):
    """`arraykernel.structure` with one part left out (a planted incomplete key)."""
    real = arraykernel.structure

    def structure(s):
        key = real(s)
        if isinstance(part, int):
            return key[:part] + key[part + 1:]
        return key[:-1] + (tuple(light[:part[1]] + light[part[1] + 1:] for light in key[-1]),)
    return structure


@pytest.mark.parametrize("part, name", [(0, "height field"), (1, "bump"), (2, "model"), (3, "sphere B"),
                                        (4, "floor"), (5, "beta = 0"), (6, "shininess"),
                                        (("light", 0), "black light"), (("light", 1), "light below the floor"),
                                        (("light", 2), "light inside a sphere")])
def test_a_structure_without_one_branch_replays_the_wrong_kernel(part, name, monkeypatch):
    """Planted: the key without one part; the pair that part tells apart then replays the first
    scene's kernel for the second, and the frame is wrong."""
    require_backend("drjit")
    monkeypatch.setattr(backends.namespace("drjit"), "_frozen", {})
    monkeypatch.setattr(arraykernel, "structure", _without(part))
    assert not _replays_right(STRUCTURE_PAIRS[name])
