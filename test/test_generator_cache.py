"""msg_defs/generator_cache.py: a generator command whose inputs have the contents of one run
before (in any clone) gets that run's output without running; other inputs run it; any other
command runs as it is. (The generator here writes one file a .idl, naming the runs: the
cache, not rosidl, is what is tested; the build of msg_defs runs the real generators.)"""
import json
import os
import subprocess
import sys

from acti_bringup.harness import ROOT

CACHE_PY = os.path.join(ROOT, "msg_defs", "generator_cache.py")
GENERATOR = """\
import json, pathlib, sys
args = json.load(open(sys.argv[sys.argv.index("--generator-arguments-file") + 1]))
out = pathlib.Path(args["output_dir"])
runs = pathlib.Path(args["runs"])
runs.write_text(runs.read_text() + "x" if runs.exists() else "x")
for item in args["idl_tuples"]:
    base, rel = item.split(":")
    text = (pathlib.Path(base) / rel).read_text()
    (out / rel).with_suffix(".h").parent.mkdir(parents=True, exist_ok=True)
    (out / rel).with_suffix(".h").write_text("// generated\\n" + text.upper())
"""


def clone(tmp_path, name: str, idl: str) -> tuple[list[str], dict]:
    """A clone's generator command: its generator, .idl input and arguments file."""
    root = tmp_path / name
    (root / "idl" / "msg").mkdir(parents=True)
    (root / "idl" / "msg" / "A.idl").write_text(idl)
    (root / "gen.py").write_text(GENERATOR)
    arguments = {"package_name": "p", "output_dir": str(root / "out"),
                 "idl_tuples": [f"{root / 'idl'}:msg/A.idl"],
                 "target_dependencies": [str(root / "gen.py")], "runs": str(tmp_path / "runs")}
    (root / "args.json").write_text(json.dumps(arguments))
    return [str(root / "gen.py"), "--generator-arguments-file", str(root / "args.json")], arguments


def run(argv: list[str], cache) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, CACHE_PY, *argv], capture_output=True, text=True,
                          env=dict(os.environ, ACTI_GENERATED_CACHE=str(cache)), timeout=60)


def test_the_same_inputs_in_another_clone_get_the_kept_output_without_a_run(tmp_path):
    cache, runs = tmp_path / "cache", tmp_path / "runs"
    first, args = clone(tmp_path, "one", "struct A { long x; };")
    assert run(first, cache).returncode == 0 and runs.read_text() == "x"
    second, args2 = clone(tmp_path, "two", "struct A { long x; };")
    assert run(second, cache).returncode == 0 and runs.read_text() == "x"     # no new run
    out = os.path.join(args2["output_dir"], "msg", "A.h")
    with open(out) as f:
        assert f.read() == "// generated\nSTRUCT A { LONG X; };"
    changed, _ = clone(tmp_path, "three", "struct A { double x; };")
    assert run(changed, cache).returncode == 0 and runs.read_text() == "xx"   # other contents


def test_any_other_command_runs_as_it_is(tmp_path):
    done = run(["-c", "import sys; print(42); sys.exit(3)"], tmp_path / "cache")
    assert (done.returncode, done.stdout) == (3, "42\n")
