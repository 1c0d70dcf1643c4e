"""Every CLI entry point fuzzed: random and adversarial arguments and malformed files give exit
code 0 or exit code 2 with one line on stderr, never a traceback or an internal error.

The argument spec of each subcommand is read from its argparse parser (so a new subcommand in
``cli.SUBCOMMANDS`` is fuzzed without editing this file); values come from pools of adversarial
numbers, strings and files (CSV with headers, pickled .npy, truncated HDF5, TOML with missing or
extra keys, negative and non-finite numbers). A few options are always given small values so
that a valid draw stays a short run.
"""

import argparse
import contextlib
import io
import os
import signal

import h5py
import matplotlib.pyplot as plt
import numpy as np
import pytest
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st

from frictionrules import FrictionContactProblem, cli, write_fclib

#: Values drawn mostly from a pool of plausible ones, else from adversarial ones.
GOOD_NUMBERS = ["0.3", "0.5", "1", "2", "60", "150", "-0.5", "-1e-6", "0.05"]
BAD_NUMBERS = ["0", "nan", "inf", "-inf", "abc", "", "1e308", "-1e308", "1,2", "0x10", "1e-320",
               "-0.5,0,0.866;0.5,0,0.866", "--", "1e-6"]
GOOD_INTEGERS = ["2", "3", "8"]
BAD_INTEGERS = ["1", "0", "-3", "abc", "1.5", "", "10000000000000", "-1e-6"]
BAD_STRINGS = ["x", "", "-", "--", "-1", "T1", "foo(T1)", "__import__('os').system('echo PWNED')",
               "T1[0]", "mu=abc", "limit=T1-N", "0,0;x", "1,2,3", "é\x00", "fig99", "a" * 300,
               "(" * 80, "2**2**2**2**2**2"]
#: Plausible values of particular options, by (subcommand, dest); files by name in the fixture.
HINTS = {
    ("law", "name"): ["coulomb", "elliptic", "huber", "transformed", "wedge", "user", "WedgeAsperity"],
    ("law", "limit"): ["sqrt(T1**2 + T2**2) - 0.3*N", "T1^2/0.36 + T2^2/0.09 - N^2"],
    ("law", "potential"): ["sqrt(T1^2 + T2^2)", "T1**2 + T2**2"],
    ("law", "param"): ["mu=0.3", "mu_x=0.6", "mu_y=0.3", "alpha=1", "local=associated",
                       "dilatant=yes", "angle=-0.5"],
    ("drive", "path"): ["@drive.toml", "@drive_missing_law.toml", "@drive_extra.toml",
                        "@drive_nan.toml", "@drive_negative.toml", "@drive_huge.toml",
                        "@drive_types.toml"],
    ("solve", "path"): ["@tiny.hdf5", "@truncated.hdf5", "@empty.hdf5", "@folder"],
    ("configuration", "config"): ["@config.toml", "@config_extra.toml", "@config_types.toml",
                                  "@config_path.toml"],
    ("configuration", "path"): ["0,0;0.1,0;0.2,0.05", "0,0;-0.1,0.05"],
    ("asperity", "config"): ["@geometry.toml", "@geometry_normals.toml", "@geometry_extra.toml"],
    ("asperity", "profile"): ["@profile.csv", "@profile_header.csv", "@garbage.csv", "@empty.csv"],
    ("asperity", "heightmap"): ["@map.npy", "@pickled.npy", "@nan.npy", "@line.npy", "@garbage.npy",
                                "@profile.csv"],
    ("asperity", "normals"): ["0,0,1", "-0.5,0,0.866;0.5,0,0.866", "0,0,1;1,0,0"],
    ("paper", "only"): ["fig1a_coulomb_cone"],
    ("export", "spec"): ["coulomb", "elliptic", "wedge", "user", "@drive.toml", "@config.toml"],
    ("export", "target"): ["abaqus-fric", "abaqus-vfric", "abaqus-uinter", "c", "ansys"],
    ("export", "limit"): ["sqrt(T1**2 + T2**2) - 0.3*N", "T1^2/0.36 + T2^2/0.09 - N^2"],
    ("export", "param"): ["mu=0.3", "mu_x=0.6", "mu_y=0.3", "alpha=1", "dilatant=yes"],
    ("export", "name"): ["law", "x1", "1x", "a_b"],
}
#: Valid command lines that the fuzzer mutates (replaces a value by an adversarial one, drops a
#: token, adds an option); ``@name`` is a fixture file, ``{out}`` the output folder.
TEMPLATES = {
    "law": [["coulomb", "--mu", "0.3", "--force", "0.2", "0.1", "--normal", "1"],
            ["elliptic", "--mu-x", "0.6", "--mu-y", "0.3", "--force", "0.3", "0.2", "--normal", "1",
             "--json"],
            ["wedge", "--alpha", "60", "--deg", "--mu", "1", "--force", "1", "0", "--normal", "1",
             "--theta", "0", "--json"],
            ["user", "--limit", "sqrt(T1^2 + T2^2) - 0.3*N", "--force", "0.3", "0", "--normal", "1"],
            ["huber", "--param", "mu_1=0.6", "--param", "mu_2=0.3", "--param", "angle=0.2",
             "--force", "0.1", "0", "--normal", "1"]],
    "configuration": [["--grain", "sphere", "--packing", "square", "--polar", "8", "--deg", "--out",
                       "{out}/p.json"],
                      ["--length", "0.3", "--direction", "-30", "--deg", "--out", "{out}/t.csv",
                       "--figure", "{out}/f.png"],
                      ["--config", "@config.toml", "--method", "incremental", "--out", "{out}/c.h5"]],
    "drive": [["@drive.toml", "--out", "{out}/d.csv", "--plot"],
              ["@drive.toml", "--out", "{out}/d.json", "--quiet"]],
    "asperity": [["--two-flank", "60", "150", "--deg", "--mu", "1", "--out", "{out}/a"],
                 ["--normals", "-0.5,0,0.866;0.5,0,0.866", "--mu", "0.4", "--format", "json",
                  "--out", "{out}/b", "--no-figure"],
                 ["--heightmap", "@map.npy", "--dx", "0.1", "--mu", "0.3", "--out", "{out}/c",
                  "--no-figure"],
                 ["--profile", "@profile.csv", "--mu", "0.3", "--out", "{out}/d", "--no-figure"]],
    "solve": [["@tiny.hdf5", "--method", "nsgs", "--csv", "{out}/s.csv"],
              ["@tiny.hdf5", "--method", "newton", "--tol", "1e-10"]],
    "paper": [["--out", "{out}/paper", "--format", "png"]],
    "export": [["coulomb", "--mu", "0.3", "--target", "abaqus-fric", "--kt", "1e4", "--out",
                "{out}/e"],
               ["elliptic", "--mu-x", "0.6", "--mu-y", "0.3", "--angle", "20", "--deg",
                "--target", "c", "--kt", "100", "--kn", "200", "--out", "{out}/c"],
               ["wedge", "--alpha", "0.3", "--mu", "0.2", "--target", "abaqus-uinter", "--kt",
                "1e4", "--kn", "1e5", "--out", "{out}/u"]],
}
#: Options that always get a value from a small pool, so that valid draws run fast.
ALWAYS = {
    "paper": {"--only": ["fig1a_coulomb_cone", "fig99", "", "-1", "fig10", "fig1a_coulomb_cone "]},
    "configuration": {"--steps": ["2", "5", "0", "-3", "abc", "10000000000000"]},
    "asperity": {"--n": ["8", "16", "0", "-5", "abc"]},
    "solve": {"--max-iter": ["20", "0", "-1", "abc"]},
}
DRIVE = """[model]
kn = 100.0
kt = 100.0
[model.law]
type = "Coulomb"
mu = 0.5
[[segment]]
N = 1.0
dt1 = 0.0
dt2 = 0.0
steps = 2
[[segment]]
dt1 = 0.05
steps = 3
"""


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """Input files, good and malformed, and output paths; returns (inputs, outputs, scratch)."""
    d = tmp_path_factory.mktemp("fuzz")
    w = {}

    def text(name, content):
        (d / name).write_text(content)
        w[name] = d / name

    text("drive.toml", DRIVE)
    text("drive_missing_law.toml", DRIVE.split("[model.law]")[0] + "[[segment]]\nN = 1.0\n")
    text("drive_extra.toml", DRIVE + "[extra]\nkey = 1\n")
    text("drive_nan.toml", DRIVE.replace("mu = 0.5", "mu = nan"))
    text("drive_negative.toml", DRIVE.replace("kn = 100.0", "kn = -100.0"))
    text("drive_huge.toml", DRIVE.replace("steps = 3", "steps = 100000000000"))
    text("drive_types.toml", DRIVE.replace("steps = 2", 'steps = "two"').replace("N = 1.0", "N = [1]"))
    text("config.toml", 'grain = "sphere"\npacking = "square"\nmu = 0.3\nsteps = 3\n')
    text("config_extra.toml", 'grain = "cylinder"\ncolour = "red"\n')
    text("config_types.toml", 'mu = "high"\nsteps = 2.5\npolar = -3\n')
    text("config_path.toml", 'path = [[0, 0], [1]]\n')
    text("geometry.toml", 'geometry = "two-flank"\nalpha1 = 60\ndeg = true\nmu = 0.5\nn = 8\n')
    text("geometry_normals.toml", 'geometry = "normals"\nnormals = [[0, 0, 1], "x"]\nmu = 0.3\n')
    text("geometry_extra.toml", 'geometry = "heightmap"\nfile = "missing.npy"\nmu = -1\nwhat = 3\n')
    text("profile_header.csv", "x,z\n0,0\n1,1\n2,0\n")
    text("profile.csv", "0,0\n1,1\n2,0\n")
    text("garbage.csv", "this is, not\na table\n")
    text("empty.csv", "")
    text("bad.toml", "mu = = 0.3\n")
    (d / "binary.toml").write_bytes(b"\xff\xfe\x00\x01")
    w["binary.toml"] = d / "binary.toml"
    np.save(d / "map.npy", np.random.default_rng(0).normal(size=(8, 8)))
    np.save(d / "pickled.npy", np.array([{"a": 1}, None], dtype=object), allow_pickle=True)
    np.save(d / "nan.npy", np.full((4, 4), np.nan))
    np.save(d / "line.npy", np.arange(5.0))
    (d / "garbage.npy").write_bytes(b"\x93NUMPY garbage")
    for name in ("map.npy", "pickled.npy", "nan.npy", "line.npy", "garbage.npy"):
        w[name] = d / name
    problem = FrictionContactProblem(np.eye(3), [-1.0, 0.5, 0.0], [0.3])
    write_fclib(d / "tiny.hdf5", problem)
    data = (d / "tiny.hdf5").read_bytes()
    (d / "truncated.hdf5").write_bytes(data[: len(data) // 2])
    (d / "notes.hdf5").write_text("not HDF5")
    with h5py.File(d / "empty.hdf5", "w") as h5:
        h5["fclib_local/vectors/q"] = [1.0, np.nan]
    for name in ("tiny.hdf5", "truncated.hdf5", "notes.hdf5", "empty.hdf5"):
        w[name] = d / name
    (d / "folder").mkdir()
    (d / "folder" / "a.hdf5").write_text("junk")
    w["folder"] = d / "folder"
    w["missing"] = d / "missing.toml"
    outputs = [d / "out" / name for name in ("o.csv", "o.json", "o.h5", "o.png", "o.svg", "o.xyz",
                                             "noext", "")]
    (d / "victim.txt").write_text("an existing file")
    outputs += [d / "folder", "/proc/frictionrules/x.csv", d / "victim.txt", d / "victim.txt" / "x.csv"]
    scratch = d / "cwd"
    scratch.mkdir()
    return {k: str(p) for k, p in w.items()}, [str(p) for p in outputs], scratch


def _parser(name):
    sub = next(a for a in cli.build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    return sub.choices[name]


_OUTPUT_WORDS = ("out", "csv", "figure", "plot", "save")
_INPUT_WORDS = ("path", "config", "profile", "heightmap", "file", "toml", "npy")


def _tokens(action, name, inputs, outputs):
    """Strategy for the value tokens of one argparse action of subcommand ``name``."""
    if action.nargs == 0:
        return st.just([])
    try:
        kind = type(action.type("2")) if action.type is not None else str
    except Exception:
        kind = str
    good = [inputs.get(v[1:], v) if v.startswith("@") else v for v in HINTS.get((name, action.dest), [])]
    if action.choices is not None:
        good, bad = [str(c) for c in action.choices], ["bogus", ""]
    elif kind is int:
        good, bad = good or GOOD_INTEGERS, BAD_INTEGERS
    elif kind is float:
        good, bad = good or GOOD_NUMBERS, BAD_NUMBERS
    elif any(w in action.dest.lower() for w in _OUTPUT_WORDS):
        good, bad = good or outputs[:5], outputs[5:] + BAD_STRINGS[:3]
    elif any(w in (action.dest + str(action.metavar)).lower() for w in _INPUT_WORDS):
        bad = list(inputs.values()) + BAD_STRINGS[:3]
    else:
        bad = BAD_STRINGS + BAD_NUMBERS
    # four plausible values to one adversarial: most draws get past the first check
    one = (st.integers(0, 4).flatmap(lambda k: st.sampled_from(bad if k == 0 else good)) if good
           else st.sampled_from(bad))
    n = action.nargs
    if isinstance(n, int):
        return st.lists(one, min_size=n, max_size=n)
    if n == "?":
        return st.lists(one, max_size=1)
    if n in ("*", "+"):
        return st.lists(one, min_size=1 if n == "+" else 0, max_size=3)
    return st.lists(one, min_size=1, max_size=1)


@st.composite
def command(draw, name, inputs, outputs):
    """A command line: a mutated valid one (when the subcommand has templates) or one built
    from random options."""
    if name in TEMPLATES and draw(st.booleans()):
        return draw(mutated(name, inputs, outputs))
    return draw(random_command(name, inputs, outputs))


@st.composite
def mutated(draw, name, inputs, outputs):
    out = os.path.dirname(outputs[0])
    argv = [name] + [inputs[t[1:]] if t.startswith("@") else t.replace("{out}", out)
                     for t in draw(st.sampled_from(TEMPLATES[name]))]
    adversarial = BAD_NUMBERS + BAD_STRINGS + list(inputs.values()) + outputs
    for _ in range(draw(st.integers(0, 2))):
        what = draw(st.sampled_from(["replace", "replace", "drop", "add"]))
        values = [i for i, t in enumerate(argv) if i > 0 and not t.startswith("--")]
        if what == "replace" and values:
            argv[draw(st.sampled_from(values))] = draw(st.sampled_from(adversarial))
        elif what == "drop" and len(argv) > 1:
            del argv[draw(st.integers(1, len(argv) - 1))]
        else:
            argv += draw(random_command(name, inputs, outputs))[1:]
    for flag, pool in ALWAYS.get(name, {}).items():
        argv += [flag, draw(st.sampled_from(pool))]
    return argv


@st.composite
def random_command(draw, name, inputs, outputs):
    parser = _parser(name)
    skip = (argparse._HelpAction, argparse._VersionAction)
    actions = [a for a in parser._actions if not isinstance(a, skip) and a.dest != "debug"]
    argv = [name]
    for a in actions:
        if not a.option_strings and draw(st.integers(0, 9)) > 0:  # a missing positional: usage error
            argv += draw(_tokens(a, name, inputs, outputs))
    fixed = ALWAYS.get(name, {})
    options = [a for a in actions if a.option_strings and not set(a.option_strings) & set(fixed)]
    chosen = [a for a in options if a.required and draw(st.integers(0, 9)) > 0]
    chosen += draw(st.lists(st.sampled_from([a for a in options if not a.required]),
                            unique_by=lambda a: a.dest, max_size=5))
    for a in chosen:
        argv += [draw(st.sampled_from(a.option_strings))] + draw(_tokens(a, name, inputs, outputs))
    for flag, pool in fixed.items():
        argv += [flag, draw(st.sampled_from(pool))]
    if draw(st.integers(0, 9)) == 0:  # a stray token anywhere
        argv.insert(draw(st.integers(1, len(argv))), draw(st.sampled_from(BAD_STRINGS + BAD_NUMBERS)))
    return argv


class Hang(BaseException):
    pass


@contextlib.contextmanager
def time_limit(seconds):
    """Fail an example that runs longer than ``seconds`` (a hang is a bug too)."""
    if not hasattr(signal, "SIGALRM"):
        yield
        return

    def alarm(*_):
        raise Hang(f"no answer in {seconds} s")
    old = signal.signal(signal.SIGALRM, alarm)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


def run(argv, cwd):
    """``main(argv)`` in ``cwd``: (exit code, stdout, stderr); an exception is re-raised with
    the command line."""
    out, err = io.StringIO(), io.StringIO()
    try:
        with contextlib.chdir(cwd), contextlib.redirect_stdout(out), contextlib.redirect_stderr(err), \
                time_limit(180):
            rc = cli.main([str(a) for a in argv])
    except BaseException as exc:
        raise AssertionError(f"frictionrules {' '.join(map(repr, argv))} raised {exc!r}") from exc
    finally:
        plt.close("all")
    return rc, out.getvalue(), err.getvalue()


def check(argv, rc, err):
    """0, or 2 with one line; 1 is an internal error, except where a command reports its own
    failures with it (solve: a problem not converged)."""
    line = f"frictionrules {' '.join(map(repr, argv))}"
    assert rc in (0, 1, 2) and "internal error" not in err, f"{line}: exit code {rc}, stderr {err!r}"
    assert "Traceback" not in err, f"{line}: {err}"
    if rc == 2:
        lines = err.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("frictionrules") and "error" in lines[0], \
            f"{line}: stderr {err!r}"


#: Examples per subcommand (default 25): fewer where a valid draw runs for seconds.
EXAMPLES = {"paper": 8, "export": 15, "law": 40, "configuration": 40, "drive": 40, "solve": 30, "asperity": 30}


@pytest.mark.parametrize("name", cli.SUBCOMMANDS)
def test_fuzz_subcommand(name, files):
    inputs, outputs, scratch = files
    phases = [Phase.explicit, Phase.reuse, Phase.generate, Phase.shrink]

    @settings(max_examples=EXAMPLES.get(name, 25), phases=phases,
              suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
    @given(data=st.data())
    def fuzz(data):
        argv = data.draw(command(name, inputs, outputs), label="argv")
        rc, _, err = run(argv, scratch)
        check(argv, rc, err)

    fuzz()


# ---- the bad inputs the issue lists: one line, exit 2 ------------------------------------------
def _issue_cases():
    #: (argv with {d} for the file folder, text the error line must contain)
    return [
        (["law", "coulomb", "--param", "mu=abc", "--force", "1", "0", "--normal", "1"], "mu = 'abc'"),
        (["law", "user", "--limit", "foo(T1)", "--force", "1", "0", "--normal", "1"], "'foo'"),
        (["configuration", "--polar", "-3"], "--polar"),
        (["configuration", "--polar", "0"], "--polar"),
        (["configuration", "--figure", "{d}/fig.xyz"], "--figure"),
        (["drive", "{d}/drive.toml", "--out", "{d}/out.xyz"], "--out"),
        (["solve", "{d}/tiny.hdf5", "--csv", "/proc/frictionrules/x.csv"], "/proc/frictionrules/x.csv"),
        (["asperity", "--two-flank", "60", "150", "--deg", "--mu", "1", "--n", "0", "--out", "{d}/a"], "n"),
        (["asperity", "--two-flank", "60", "150", "--deg", "--mu", "1", "--n", "-5", "--out", "{d}/a"], "n"),
        (["asperity", "--heightmap", "{d}/garbage.npy", "--mu", "0.3", "--n", "8", "--out", "{d}/a"],
         "garbage.npy"),
        (["asperity", "--config", "{d}/geometry.toml", "--out", "{d}/a"], "alpha2"),
        (["asperity", "--dx", "-1e-6", "--heightmap", "{d}/map.npy", "--mu", "0.3", "--n", "8",
          "--out", "{d}/a"], "dx"),
    ]


@pytest.mark.parametrize("argv, text", _issue_cases(), ids=lambda v: " ".join(v)[:60] if isinstance(v, list) else None)
def test_issue_inputs_are_one_line_errors(argv, text, files):
    inputs, _, scratch = files
    d = os.path.dirname(inputs["drive.toml"])
    argv = [a.replace("{d}", d) for a in argv]
    rc, _, err = run(argv, scratch)
    check(argv, rc, err)
    assert rc == 2 and text in err and ".x.csv." not in err, err


def test_a_csv_header_line_is_read(files):
    """A profile whose first line names its columns (x,z) is data, not an error."""
    inputs, _, scratch = files
    d = os.path.dirname(inputs["drive.toml"])
    rc, _, err = run(["asperity", "--profile", f"{d}/profile_header.csv", "--mu", "0.3", "--n", "8",
                      "--no-figure", "--out", f"{d}/header"], scratch)
    assert rc == 0, err


def test_negative_numbers_are_values(files):
    """argparse would take these for options: they are values everywhere."""
    inputs, _, scratch = files
    d = os.path.dirname(inputs["drive.toml"])
    rc, _, err = run(["asperity", "--normals", "-0.5,0,0.866;0.5,0,0.866", "--mu", "0.4", "--n",
                      "8", "--no-figure", "--out", f"{d}/neg"], scratch)
    assert rc == 0, err
    rc, out, err = run(["configuration", "--direction", "-30", "--deg", "--steps", "3", "--length",
                        "0.2", "-Q", "2"], scratch)
    assert rc == 0 and "3 points" in out, err
