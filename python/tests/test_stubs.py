"""The type stubs (morphfx.pyi) describe the module: mypy's stubtest holds
every name, signature and default to the module as built, and mypy checks
the README's example against them."""

import re
import subprocess
import sys
from pathlib import Path

import morphfx

ROOT = Path(__file__).resolve().parents[2]


def test_the_stubs_ship_with_the_module():
    installed = Path(morphfx.__file__).parent
    assert (installed / "py.typed").is_file() and (installed / "__init__.pyi").is_file()


def test_the_stubs_match_the_module():
    done = subprocess.run(
        [sys.executable, "-m", "mypy.stubtest", "morphfx",
         "--allowlist", str(ROOT / "python" / "stubtest-allowlist.txt")],
        capture_output=True, text=True)
    assert done.returncode == 0, done.stdout + done.stderr


def test_the_readme_example_type_checks(tmp_path):
    example = re.search(r"## Python.*?```python\n(.*?)```", (ROOT / "README.md").read_text(),
                        re.S).group(1)
    (tmp_path / "example.py").write_text(example)
    done = subprocess.run([sys.executable, "-m", "mypy", "--strict", "example.py"],
                          capture_output=True, text=True, cwd=tmp_path)
    assert done.returncode == 0, done.stdout + done.stderr


def test_a_misused_call_fails_the_type_check(tmp_path):
    """The stubs say something: a wrong call is caught."""
    (tmp_path / "wrong.py").write_text("import morphfx\nmorphfx.morph(1, 2)\n")
    done = subprocess.run([sys.executable, "-m", "mypy", "wrong.py"], capture_output=True,
                          text=True, cwd=tmp_path)
    assert done.returncode == 1 and "morph" in done.stdout, done.stdout


def test_tool_defaults_are_the_command_lines(cli):
    """The stubs' defaults are held to the module above; the module's are
    held here to `morphfx COMMAND --help`."""
    import inspect
    for command, options in [
        ("track", ["radius", "min_correlation"]),
        ("snap", ["sigma", "iterations"]),
        ("suggest", ["count", "min_confidence"]),
    ]:
        help_text = cli(command, "--help").stdout
        params = inspect.signature(getattr(morphfx, command)).parameters
        for name in options:
            option = "--" + name.replace("_", "-")
            shown = re.search(re.escape(option) + r" <[^>]+>\s+.*?\[default: ([0-9.]+)\]",
                              help_text, re.S).group(1)
            assert float(shown) == params[name].default, (command, option)
