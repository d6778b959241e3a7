"""The README is run: its Python blocks execute, its console transcripts match the real output.

The README must read in five minutes and stay true: it opens with the two commands (``make demo``,
``make test``), its ``sh`` commands are the ones CI runs (``.ci/run`` and the Makefile targets it
calls), every ``python`` block runs as written (in a temporary folder where ``tests/`` is this
repository's), and every ``console`` transcript gives exactly the output shown (only timings could
be tolerated, and the README's transcripts show none).
"""

import pathlib
import re
import shlex

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
MAKEFILE = ROOT / "Makefile"
CI = ROOT / ".ci" / "run"

BLOCK = re.compile(r"^```(\w+)\n(.*?)^```", re.S | re.M)


def blocks(language):
    return [body for lang, body in BLOCK.findall(README.read_text(encoding="utf-8")) if lang == language]


def commands(body):
    """The commands of an ``sh`` block, without their comments."""
    lines = (line.split("#", 1)[0].strip() for line in body.splitlines())
    return [line for line in lines if line]


def make_targets_run_by_ci():
    """The make targets that ``.ci/run`` calls, with the targets those depend on or call."""
    makefile = MAKEFILE.read_text(encoding="utf-8")
    recipes = {}
    for match in re.finditer(r"^([\w-]+):([^\n]*)\n((?:\t[^\n]*\n)*)", makefile, re.M):
        recipes[match.group(1)] = (match.group(2), match.group(3))
    todo = re.findall(r"^make ([\w-]+)", CI.read_text(encoding="utf-8"), re.M)
    seen = set()
    while todo:
        target = todo.pop()
        if target in seen or target not in recipes:
            continue
        seen.add(target)
        prerequisites, recipe = recipes[target]
        todo += re.findall(r"[\w-]+", prerequisites) + re.findall(r"\$\(MAKE\) ([\w-]+)", recipe)
    return seen, recipes


def test_the_readme_is_short_and_speaks_to_users():
    text = README.read_text(encoding="utf-8")
    assert len(text.splitlines()) <= 250
    for word in ("issue", "seed", "closing note", "stop "):
        assert word not in text.lower(), word


def test_the_readme_opens_with_the_two_commands():
    first = blocks("sh")[0]
    assert commands(first) == ["make demo", "make test"]
    text = README.read_text(encoding="utf-8")
    assert text.index("```sh") < text.index("\n## ")  # before any section
    ci_targets = re.findall(r"^make ([\w-]+)", CI.read_text(encoding="utf-8"), re.M)
    assert "test" in ci_targets and "demo" in ci_targets


def test_every_sh_command_is_run_by_ci_or_a_make_target():
    targets, recipes = make_targets_run_by_ci()
    run_by_ci = "\n".join(recipe for name, (_, recipe) in recipes.items() if name in targets)
    for body in blocks("sh"):
        for command in commands(body):
            if command.startswith("make "):  # a target of the Makefile (make quick: a part of make test)
                assert command.split()[1] in recipes, command
                continue
            for part in command.split("&&"):  # each step, as the Makefile spells it
                words = part.split()
                if words[0] in ("pip", "python"):
                    words = words[1:] if words[0] == "python" else ["-m", "pip", *words[1:]]
                step = " ".join(words).replace("'", "")
                assert step in run_by_ci.replace("'", ""), f"{command!r}: {step!r} not run by CI"


def test_the_links_and_pictures_exist():
    text = README.read_text(encoding="utf-8")
    targets = re.findall(r"\]\(([^)#]+)(?:#[^)]*)?\)", text)
    assert any(target.endswith(".png") for target in targets)
    for target in targets:
        assert (ROOT / target).is_file(), target


# the modules each Python block needs beyond the core (the blocks skip without them)
_NEEDS = {
    "trimesh": ("trimesh", "pyvista"),
    "label_curvatures": ("skimage", "pandas"),
    "write_curvatures": (),
}


@pytest.fixture
def readme_folder(tmp_path, monkeypatch):
    """A temporary working folder in which ``tests/data`` is this repository's."""
    (tmp_path / "tests").symlink_to(ROOT / "tests", target_is_directory=True)
    monkeypatch.chdir(tmp_path)
    return tmp_path


@pytest.mark.parametrize("index", range(len(blocks("python"))))
def test_python_block_runs(index, readme_folder, capsys):
    code = blocks("python")[index]
    for key, modules in _NEEDS.items():
        if key in code:
            for module in modules:
                pytest.importorskip(module)
    exec(compile(code, f"README.md, python block {index + 1}", "exec"), {"__name__": "__readme__"})
    assert capsys.readouterr().out  # each block shows something


def transcript_steps(body):
    """``(command, expected output lines)`` of a console transcript."""
    steps = []
    for line in body.splitlines():
        if line.startswith("$ "):
            steps.append((line[2:].split("  #")[0].strip(), []))
        else:
            steps[-1][1].append(line)
    return steps


TIMING = re.compile(r"\d+(\.\d+)? ?(s|ms|min)\b")


def same_output(expected, actual):
    """Lines equal, but for the numbers of timings (``1.2 s``, ``35 ms``)."""
    return len(expected) == len(actual) and all(
        TIMING.sub("TIME", want).rstrip() == TIMING.sub("TIME", got).rstrip() for want, got in zip(expected, actual)
    )


@pytest.mark.slow  # meshcurv compute and plot, cold: several seconds
@pytest.mark.parametrize("index", range(len(blocks("console"))))
def test_console_transcript_is_the_real_output(index, readme_folder, capsys):
    pytest.importorskip("matplotlib")  # meshcurv plot
    from meshcurv.cli import main

    for command, expected in transcript_steps(blocks("console")[index]):
        argv = shlex.split(command)
        assert argv[0] == "meshcurv", command
        code = main(argv[1:])
        out, err = capsys.readouterr()
        actual = (out + err).splitlines()
        assert code == 0, f"{command}: exit {code}\n{err}"
        assert same_output(expected, actual), (
            f"{command}\nREADME:\n" + "\n".join(expected) + "\nreal:\n" + "\n".join(actual)
        )


def test_every_console_command_is_checked():
    # the transcripts hold commands only of the meshcurv program (run in-process above)
    for body in blocks("console"):
        assert all(command.startswith("meshcurv ") for command, _ in transcript_steps(body))


def test_the_timing_rule_tolerates_only_timings():
    assert same_output(["took 1.2 s"], ["took 0.8 s"])
    assert not same_output(["area 5.70952"], ["area 5.70953"])
    assert not same_output(["a"], ["a", "b"])
