"""`barhinge dof` command and the local-DOF picture."""

from __future__ import annotations

import json

import numpy as np
import pytest
import scipy.sparse as sp
from typer.testing import CliRunner

import barhinge as bh
from barhinge.cli import app


def test_dof_command_json_and_png(tmp_path):
    png = tmp_path / "dof.png"
    res = CliRunner().invoke(app, ["dof", "miura:nx=2,ny=2", "--json", "--png", str(png)])
    assert res.exit_code == 0, res.output
    data = json.loads(res.output)
    direct = bh.dof(bh.families.miura(2, 2))
    assert data["state"]["global_dof"] == direct.global_dof
    assert data["state"]["counted_dof"] == direct.counted_dof
    assert data["folded_state"]["global_dof"] == 1
    assert data["folded_state"]["redundant"] == 1 - direct.counted_dof
    assert data["folded_state"]["actuators"] == direct.folded.actuators.tolist()
    assert png.stat().st_size > 5000
    with open(png, "rb") as fh:
        assert fh.read(8) == b"\x89PNG\r\n\x1a\n"


def test_dof_command_table_and_bad_pattern():
    res = CliRunner().invoke(app, ["dof", "miura:nx=2,ny=2", "--triangulated"])
    assert res.exit_code == 0, res.output
    assert "counted DOF" in res.output and "redundant" in res.output
    bad = CliRunner().invoke(app, ["dof", "no_such_family:n=2"])
    assert bad.exit_code != 0


def test_draw_dof_returns_figure_with_actuators_marked():
    from barhinge.plot.dof import draw_dof

    cp = bh.families.miura(2, 2)
    rep = bh.dof(cp)
    fig = draw_dof(cp, rep, which="local")
    ax = fig.axes[0]
    # three line collections (creases, boundary, actuators) and one scatter of vertices
    assert len(ax.collections) == 4
    offsets = ax.collections[-1].get_offsets()
    assert len(offsets) == int(np.sum(rep.folded.local >= 0))
    # every actuator's edge id is written beside it (the ids `barhinge dof` prints)
    acts = [int(e) for e in rep.mechanism.actuators]
    assert sorted(int(t.get_text()) for t in ax.texts) == sorted(acts)
    n = len(acts)
    assert f"{n} actuator{'' if n == 1 else 's'};" in ax.get_title()
    import matplotlib.pyplot as plt

    plt.close(fig)


def test_dof_command_states_the_gap_and_library_failures_exit_3(monkeypatch):
    """The table shows the singular values on both sides of the cut and the gap ratio; a
    failing numerical library is a one-line error with exit code 3, not a traceback."""
    from barhinge.cli import main
    from barhinge.linalg import nullspace as nsm

    res = CliRunner().invoke(app, ["dof", "miura:nx=2,ny=2"])
    assert res.exit_code == 0, res.output
    assert "gap ratio" in res.output and "certain" in res.output
    data = json.loads(CliRunner().invoke(app, ["dof", "miura:nx=2,ny=2", "--json"]).output)
    assert data["folded_state"]["certain"] is True
    assert data["folded_state"]["gap_ratio"] > 1e3
    assert data["folded_state"]["dof_range"] == [1, 1]

    class Broken:
        def factorize(self, A):
            raise RuntimeError("simulated MKL failure")

    monkeypatch.setattr(nsm, "_backend", lambda name: Broken())
    monkeypatch.setattr(nsm, "_dense", lambda J, tol, g: nsm._sparse(sp.csr_matrix(J), tol, g))

    with pytest.raises(SystemExit) as exc:
        main(["dof", "miura:nx=2,ny=2", "--json"])
    assert exc.value.code == 3


def test_local_dof_library_failure_exits_3(monkeypatch, capsys):
    """An SVD that does not converge in the local-DOF stage is a RankError (exit 3, one
    line), not numpy's traceback."""
    import importlib

    from barhinge.cli import main

    dofm = importlib.import_module("barhinge.kinematics.dof")

    def broken(*a, **k):
        raise np.linalg.LinAlgError("SVD did not converge")

    monkeypatch.setattr(dofm, "local_dof", broken)
    with pytest.raises(SystemExit) as exc:
        main(["dof", "miura:nx=2,ny=2", "--json"])
    assert exc.value.code == 3
    err = capsys.readouterr().err
    assert "SVD did not converge" in err and "Traceback" not in err
