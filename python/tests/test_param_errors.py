"""The library's own errors name parameters (ParamError, vdbhair/Parameters.h): Python gives them
as its keywords, the command line as its flags, from the same declaration and without either
rewriting the other's text."""
import subprocess

import pytest

import vdbhair
from conftest import straight_bundle, wavy_hairstyle
from test_defaults import cli


def test_a_rule_the_library_checks_names_the_keyword():
    # match balance: 0 or at least 1, a rule the declared range cannot say (DetailMatchParams::validate).
    with pytest.raises(vdbhair.ArgumentError, match=r"^synth: match_balance 0\.5: 0 \(off\) or a finite factor of at least 1$"):
        vdbhair.synth(wavy_hairstyle(count=40), match_balance=0.5)
    with pytest.raises(ValueError, match=r"^color_by error needs a reference hairstyle"):
        vdbhair.render(straight_bundle(), color_by="error")
    with pytest.raises(ValueError, match=r"^compare: unit 'furlong': expected mm, cm, dm, m, in or the unit's length in metres"):
        vdbhair.compare(straight_bundle(), straight_bundle(), unit="furlong")


def test_the_command_line_names_the_same_rule_by_its_flag(tmp_path):
    path = tmp_path / "wavy.hair"
    wavy_hairstyle(count=40).write(str(path))
    run = subprocess.run([cli(), "synth", str(path), "-o", str(tmp_path / "out.hair"), "--match-balance", "0.5"],
                         capture_output=True, text=True)
    assert run.returncode == 2
    assert run.stderr.strip().endswith("--match-balance 0.5: 0 (off) or a finite factor of at least 1")
