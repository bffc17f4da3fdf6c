"""The shell environment: `source tools/env.sh` is the way in (it keeps what was on the paths
and puts the console scripts on PATH); `source .venv/bin/activate` alone says so."""
import os
import subprocess

from acti_bringup.harness import ROOT

SCRIPTS = ("acti_robot", "acti_middle_node", "vehicle_node")


def bash(script: str, **env: str) -> subprocess.CompletedProcess:
    clean = {k: v for k, v in os.environ.items()
             if k not in ("AMENT_PREFIX_PATH", "CMAKE_PREFIX_PATH", "VIRTUAL_ENV")}
    return subprocess.run(["bash", "-c", script], cwd=ROOT, capture_output=True, text=True,
                          env={**clean, **env}, timeout=60)


def test_env_sh_prepends_to_the_prefix_paths_once_and_keeps_what_was_there(tmp_path):
    other = str(tmp_path)
    done = bash("source tools/env.sh && source tools/env.sh && "
                "echo $AMENT_PREFIX_PATH && echo $CMAKE_PREFIX_PATH",
                AMENT_PREFIX_PATH=other, CMAKE_PREFIX_PATH=other)
    ament, cmake = done.stdout.split()
    venv = os.path.join(ROOT, ".venv")
    assert ament.split(":")[-2:] == [venv, other], ament
    assert cmake.split(":")[-2:] == [venv, other], cmake
    assert len(ament.split(":")) == len(set(ament.split(":")))


def test_the_console_scripts_are_on_path_after_env_sh():
    done = bash("source tools/env.sh && for s in " + " ".join(SCRIPTS) + "; do command -v $s; done")
    found = done.stdout.split()
    assert [os.path.basename(p) for p in found] == list(SCRIPTS), done.stdout + done.stderr
    assert all(p.startswith(os.path.join(ROOT, "install")) for p in found)


def test_the_venv_alone_says_how_to_enter_the_environment_and_env_sh_is_quiet():
    alone = bash("source .venv/bin/activate")
    assert f"source {ROOT}/tools/env.sh" in alone.stderr, alone.stderr
    assert bash("source tools/env.sh").stderr == ""
