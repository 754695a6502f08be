"""Model.measure (python/frepfarm_module.cpp, docs/measure.md): certified mass properties
against closed forms, the dict frep measure --json prints."""
import math

import pytest

import frepfarm

BALL = """my_model(x[3], a[1]) {
  array c[3];
  c = [0.3, -0.2, 0.15];
  my_model = hfSphere(x, c, a[1]);
}"""
TORUS = """my_model(x[3], a[1]) {
  array c[3];
  c = [0, 0, 0];
  my_model = hfTorusZ(x, c, 1, 0.3);
}"""


def holds(b, exact, rel_width=None):
    assert b["lower"] <= exact <= b["upper"], (b, exact)
    if rel_width is not None:
        assert b["upper"] - b["lower"] <= rel_width * abs(exact), (b, exact)


def test_ball_volume_area_centroid_inertia():
    r = 0.8
    m = frepfarm.compile(BALL, file="ball.hf", params=[r])
    d = m.measure(lo=(-1.5, -1.5, -1.5), hi=(1.5, 1.5, 1.5))
    v = 4 / 3 * math.pi * r ** 3
    holds(d["volume"], v, 0.005)
    holds(d["area"], 4 * math.pi * r * r, 0.005)
    for b, c in zip(d["centroid"], (0.3, -0.2, 0.15)):
        holds(b, c)
    assert d["inertia_about"] == "centroid"
    for i in range(3):
        holds(d["inertia"][i][i], 0.4 * v * r * r, 0.02)
        for k in range(3):
            if k != i:
                holds(d["inertia"][i][k], 0.0)
    assert d["tolerance_reached"] and d["area_bounded"] and d["cut_faces"] == []


def test_torus_by_pappus():
    d = frepfarm.compile(TORUS).measure(lo=(-1.5, -1.5, -0.5), hi=(1.5, 1.5, 0.5), tolerance=0.01)
    holds(d["volume"], 2 * math.pi ** 2 * 1 * 0.3 ** 2, 0.01)
    holds(d["area"], 4 * math.pi ** 2 * 1 * 0.3, 0.01)


def test_cut_by_the_box_and_threads_give_the_same_numbers():
    m = frepfarm.compile(BALL, params=[1.0])
    a = m.measure(lo=(-1.5, -1.5, 0.15), hi=(1.5, 1.5, 1.5), tolerance=0.01, threads=1)
    b = m.measure(lo=(-1.5, -1.5, 0.15), hi=(1.5, 1.5, 1.5), tolerance=0.01, threads=2)
    assert a == b
    holds(a["volume"], 2 / 3 * math.pi, 0.01)  # the upper half (the centre is at z = 0.15)
    holds(a["cut_area"], math.pi, 0.01)
    assert a["cut_faces"] == ["z-min"]


def test_measure_refuses_bad_arguments():
    m = frepfarm.compile(BALL, params=[1.0])
    with pytest.raises(ValueError, match="tolerance"):
        m.measure(tolerance=0)
    with pytest.raises(ValueError, match="hi > lo"):
        m.measure(lo=(1, 1, 1), hi=(0, 2, 2))
    flat = frepfarm.compile("my_model(x[2], a[1]) { my_model = 1 - x[1]^2 - x[2]^2; }")
    with pytest.raises(ValueError, match="3D"):
        flat.measure()
