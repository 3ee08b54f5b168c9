"""The Python package against the `pathlight` program and against itself.

Images are compared bit for bit: the same scene, seed and backend render the same sums
whatever drives the renderer, and the state files' sums are exact. The program is
`$PATHLIGHT_BIN` (tools/test-python.sh points it at cargo's build).
"""

import os
import signal
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import pathlight

REPO = Path(__file__).resolve().parents[2]
CORNELL = REPO / "scenes" / "refs" / "cornell-spheres.toml"
BOX = REPO / "crates" / "scene" / "tests" / "data" / "gltf" / "BoxTextured-glTF-Binary" / "BoxTextured.glb"
SUNRISE = REPO / "assets" / "env" / "sunrise.exr"
PATHLIGHT = os.environ.get("PATHLIGHT_BIN", str(REPO / "target" / "debug" / "pathlight"))


def cli_render(tmp_path, *args):
    """The image `pathlight render ARGS -o image.exr` writes."""
    out = tmp_path / "cli.exr"
    subprocess.run([PATHLIGHT, "render", *map(str, args), "-o", str(out)], check=True,
                   capture_output=True)
    return pathlight.read_exr(out)


def small_room(color):
    """A tiny scene as data: a lit box around a sphere of colour `color`."""
    wall = {"color": [0.7, 0.7, 0.7]}
    return {
        "camera": {"position": [0, 1, 3.5], "look_at": [0, 1, 0], "fov_y": 45,
                   "resolution": [24, 16]},
        "render": {"spp": 4, "max_depth": 6, "seed": 7},
        "materials": {"wall": wall, "ball": {"color": color, "preset": "plastic"},
                      "lamp": {"color": [0, 0, 0], "emission": [8, 8, 8]}},
        "quad": [
            {"material": "wall", "origin": [-2, 0, 2], "edge_u": [4, 0, 0],
             "edge_v": [0, 0, -4]},
            {"material": "lamp", "origin": [-0.5, 1.99, -0.5], "edge_u": [1, 0, 0],
             "edge_v": [0, 0, 1]},
        ],
        "sphere": [{"material": "ball", "center": [0, 0.6, 0], "radius": 0.6}],
    }


def test_the_default_scene_renders_as_the_cli_renders_it(tmp_path):
    scene = pathlight.default_scene()
    image = pathlight.render(scene, spp=3, seed=5, width=40, height=30, backend="cpu")
    assert image.dtype == np.float32 and image.shape == (30, 40, 3)
    expected = cli_render(tmp_path, "--backend", "cpu", "--spp", 3, "--seed", 5,
                          "--width", 40, "--height", 30)
    assert np.array_equal(image, expected)
    assert image.mean() > 0.05


def test_images_are_written_with_the_cli_bytes(tmp_path):
    scene = pathlight.default_scene()
    image = pathlight.render(scene, spp=2, width=24, height=16, backend="cpu")
    for extension in ["png", "exr"]:
        cli = tmp_path / f"cli.{extension}"
        subprocess.run([PATHLIGHT, "render", "--backend", "cpu", "--spp", "2", "--width", "24",
                        "--height", "16", "-o", str(cli)], check=True, capture_output=True)
        ours = tmp_path / f"python.{extension}"
        pathlight.write_image(ours, image)
        assert ours.read_bytes() == cli.read_bytes(), extension
    with pytest.raises(ValueError, match=r"image\.tiff: unknown image format"):
        pathlight.write_image(tmp_path / "image.tiff", image)
    with pytest.raises(ValueError, match=r"shape \(16, 24, 4\)"):
        pathlight.write_image(tmp_path / "image.png", np.zeros((16, 24, 4), np.float32))


def test_a_reference_scene_renders_as_the_cli_renders_it_on_both_backends(tmp_path):
    scene = pathlight.load(CORNELL)
    for backend in ["cpu", "gpu"]:
        image = pathlight.render(scene, spp=2, width=32, height=32, backend=backend)
        expected = cli_render(tmp_path, CORNELL, "--backend", backend, "--spp", 2,
                              "--width", 32, "--height", 32)
        assert np.array_equal(image, expected), backend


def test_progressive_steps_equal_one_render():
    scene = pathlight.load(small_room([0.8, 0.2, 0.2]))
    renderer = pathlight.Renderer(scene, backend="cpu")
    assert renderer.step(2) == 2
    assert renderer.step(3) == 5
    assert renderer.samples == 5
    whole = pathlight.render(scene, spp=5, backend="cpu")
    assert np.array_equal(renderer.image(), whole)


def test_resumed_and_merged_renders_equal_the_whole(tmp_path):
    scene = pathlight.load(small_room([0.2, 0.8, 0.2]))
    whole = pathlight.render(scene, spp=6, backend="cpu")

    first = pathlight.Renderer(scene, backend="cpu")
    first.step(2)
    first.save_state(tmp_path / "first.state")
    second = pathlight.Renderer(scene, backend="cpu", first_sample=2)
    second.step(4)
    second.save_state(tmp_path / "second.state")
    merged = pathlight.merge([tmp_path / "first.state", tmp_path / "second.state"],
                             output=tmp_path / "merged.state")
    assert np.array_equal(merged, whole)

    resumed = pathlight.Renderer(scene, backend="cpu")
    resumed.resume(tmp_path / "first.state")
    assert resumed.samples == 2
    resumed.step(4)
    assert np.array_equal(resumed.image(), whole)

    again = pathlight.Renderer(scene, backend="cpu")
    again.resume(tmp_path / "merged.state")
    assert again.samples == 6 and np.array_equal(again.image(), whole)


def test_the_cli_resumes_a_state_python_saved(tmp_path):
    scene = pathlight.load(CORNELL)
    renderer = pathlight.Renderer(scene, backend="cpu", width=16, height=16)
    renderer.step(2)
    renderer.save_state(tmp_path / "part.state")
    out = tmp_path / "resumed.exr"
    subprocess.run([PATHLIGHT, "render", str(CORNELL), "--backend", "cpu", "--width", "16",
                    "--height", "16", "--spp", "5", "--resume", str(tmp_path / "part.state"),
                    "-o", str(out)], check=True, capture_output=True)
    whole = pathlight.render(scene, spp=5, width=16, height=16, backend="cpu")
    assert np.array_equal(pathlight.read_exr(out), whole)


def test_a_state_of_another_render_is_refused(tmp_path):
    scene = pathlight.load(small_room([0.8, 0.8, 0.2]))
    renderer = pathlight.Renderer(scene, backend="cpu")
    renderer.step(1)
    renderer.save_state(tmp_path / "room.state")
    other = pathlight.Renderer(scene, backend="cpu", seed=99)
    with pytest.raises(pathlight.RenderError, match="it is another render: .*seed"):
        other.resume(tmp_path / "room.state")


def test_a_changed_material_renders_as_a_scene_made_with_it():
    renderer = pathlight.Renderer(pathlight.load(small_room([0.8, 0.2, 0.2])), backend="cpu")
    renderer.step(2)
    red = renderer.image()
    renderer.set_material("ball", color=[0.1, 0.3, 0.9], preset=None, roughness=0.4,
                          model="metal-rough")
    assert renderer.samples == 0
    renderer.step(2)
    blue_room = small_room([0.1, 0.3, 0.9])
    blue_room["materials"]["ball"] = {"color": [0.1, 0.3, 0.9], "roughness": 0.4,
                                      "model": "metal-rough"}
    expected = pathlight.render(pathlight.load(blue_room), spp=2, backend="cpu")
    assert np.array_equal(renderer.image(), expected)
    assert not np.array_equal(red, expected)


def test_a_moved_camera_renders_as_a_scene_made_with_it():
    room = small_room([0.5, 0.5, 0.5])
    scene = pathlight.load(room)
    scene.set_camera(position=[1, 1.5, 3], width=20)
    assert scene.camera["width"] == 20
    image = pathlight.render(scene, spp=2, backend="cpu")
    room["camera"].update(position=[1, 1.5, 3], resolution=[20, 16])
    assert np.array_equal(image, pathlight.render(pathlight.load(room), spp=2, backend="cpu"))
    renderer = pathlight.Renderer(pathlight.load(small_room([0.5, 0.5, 0.5])), backend="cpu")
    renderer.set_camera(position=[1, 1.5, 3], width=20)
    renderer.step(2)
    assert np.array_equal(renderer.image(), image)


def test_bad_scenes_and_values_raise_with_the_message(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("[camera]\nposition = [0, 0, 1]\nlook_at = [0, 0, 0]\nfov_y = 400\n"
                   "resolution = [8, 8]\n")
    with pytest.raises(pathlight.SceneError, match=r"bad\.toml.*fov_y = 400"):
        pathlight.load(bad)
    with pytest.raises(pathlight.SceneError, match=r"missing\.toml"):
        pathlight.load(tmp_path / "missing.toml")
    room = small_room([0.5, 0.5, 0.5])
    room["materials"]["ball"]["color"] = [0.5, -1, 0.5]
    with pytest.raises(pathlight.SceneError, match=r"materials\.ball\.color"):
        pathlight.load(room)
    room["materials"]["ball"]["color"] = {1, 2}
    with pytest.raises(TypeError, match=r"materials\.ball\.color: a set"):
        pathlight.load(room)
    scene = pathlight.load(small_room([0.5, 0.5, 0.5]))
    with pytest.raises(KeyError, match='no material "chalk".*ball, lamp, wall'):
        scene.set_material("chalk", color=[1, 1, 1])
    with pytest.raises(pathlight.SceneError, match=r"materials\.ball\.roughness"):
        scene.set_material("ball", roughness=0.5)
    with pytest.raises(ValueError, match="fov_y = 0"):
        scene.set_camera(fov_y=0)
    with pytest.raises(TypeError, match='set_camera has no key "fov": it takes position'):
        scene.set_camera(fov=30)
    with pytest.raises(ValueError, match="spp = 0"):
        pathlight.render(scene, spp=0)
    with pytest.raises(ValueError, match='backend "tpu": use "auto", "gpu" or "cpu"'):
        pathlight.Renderer(scene, backend="tpu")
    # A refused change leaves the scene as it was.
    assert np.array_equal(pathlight.render(scene, spp=1, backend="cpu"),
                          pathlight.render(pathlight.load(small_room([0.5, 0.5, 0.5])), spp=1,
                                           backend="cpu"))


def test_auxiliary_images_and_denoising():
    scene = pathlight.load(small_room([0.8, 0.2, 0.2]))
    renderer = pathlight.Renderer(scene, backend="cpu", aovs=True)
    renderer.step(2)
    albedo, normal = renderer.albedo(), renderer.normal()
    assert albedo.shape == normal.shape == (16, 24, 3)
    assert 0 <= albedo.min() and albedo.max() <= 1 and np.abs(normal).max() <= 1.0001
    denoised = pathlight.denoise(renderer.image(), albedo=albedo, normal=normal, mode="fast")
    assert denoised.shape == (16, 24, 3) and np.isfinite(denoised).all()
    with pytest.raises(pathlight.RenderError, match="aovs=True"):
        pathlight.Renderer(scene, backend="cpu").albedo()


def test_ctrl_c_stops_a_long_render_keeping_its_samples():
    # A child started from a background job of a non-interactive shell inherits SIGINT
    # ignored, and Python then installs no handler of its own: restore it, as a terminal has.
    script = textwrap.dedent(f"""
        import signal, sys, pathlight
        signal.signal(signal.SIGINT, signal.default_int_handler)
        renderer = pathlight.Renderer(pathlight.default_scene(), backend="cpu", width=200,
                                      height=200)
        renderer.step(1)
        print("rendering", flush=True)
        try:
            renderer.step(100000)
        except KeyboardInterrupt:
            print("interrupted", renderer.samples, renderer.image().mean() > 0, flush=True)
    """)
    process = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True)
    assert process.stdout.readline().strip() == "rendering"
    time.sleep(1.0)
    sent = time.monotonic()
    process.send_signal(signal.SIGINT)
    out, _ = process.communicate(timeout=60)
    stopped = time.monotonic() - sent
    words = out.split()
    assert words[0] == "interrupted" and 1 <= int(words[1]) < 100000 and words[2] == "True"
    assert stopped < 10, f"took {stopped:.1f} s to stop"


def test_rendering_lets_other_python_threads_run():
    renderer = pathlight.Renderer(pathlight.default_scene(), backend="cpu", width=160,
                                  height=160)
    renderer.step(1)
    worker = threading.Thread(target=renderer.step, args=(12,))
    started = time.monotonic()
    worker.start()
    ticks = 0
    while worker.is_alive():
        time.sleep(0.001)
        ticks += 1
    seconds = time.monotonic() - started
    assert renderer.samples == 13
    # With the GIL held through each backend step (a fraction of a second) this thread would
    # wake a few times per step; released, it wakes every millisecond or so.
    assert ticks > 100 * seconds, f"{ticks} wake-ups in {seconds:.2f} s"


def test_the_example_sweep_runs(tmp_path):
    out = tmp_path / "sweep.png"
    subprocess.run([sys.executable, str(REPO / "examples" / "python" / "roughness_sweep.py"),
                    "--spp", "1", "--size", "16", "--roughness", "0.1", "0.9", "--backend",
                    "cpu", "-o", str(out)], check=True, capture_output=True)
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_a_gltf_file_under_a_map_renders_as_the_cli_renders_it(tmp_path):
    size = ["--width", 24, "--height", 16, "--spp", 2, "--backend", "cpu"]
    scene = pathlight.load(BOX)
    grey = pathlight.render(scene, spp=2, width=24, height=16, backend="cpu")
    assert np.array_equal(grey, cli_render(tmp_path, BOX, *size))
    # After a render (the scene prepared) as before one.
    scene.set_environment(map=SUNRISE, strength=0.5, rotation=30)
    lit = pathlight.render(scene, spp=2, width=24, height=16, backend="cpu")
    expected = cli_render(tmp_path, BOX, *size, "--env", SUNRISE, "--env-strength", 0.5,
                          "--env-rotation", 30)
    assert np.array_equal(lit, expected)
    fresh = pathlight.load(BOX)
    fresh.set_environment(map=SUNRISE, strength=0.5, rotation=30)
    assert np.array_equal(pathlight.render(fresh, spp=2, width=24, height=16, backend="cpu"),
                          expected)
    scene.set_environment(strength=2)
    brighter = pathlight.render(scene, spp=2, width=24, height=16, backend="cpu")
    assert np.array_equal(brighter, cli_render(tmp_path, BOX, *size, "--env", SUNRISE,
                                               "--env-strength", 2, "--env-rotation", 30))
    scene.set_environment(radiance=[0, 0, 0])
    assert pathlight.render(scene, spp=1, width=24, height=16, backend="cpu").max() == 0
    with pytest.raises(ValueError, match="need an environment map"):
        scene.set_environment(rotation=10)
    with pytest.raises(ValueError, match="camera chooses a camera of a glTF file"):
        pathlight.load(CORNELL, camera=0)
