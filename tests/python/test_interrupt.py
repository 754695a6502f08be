"""Long calls of the Python module under the core's interrupter (python/interruptible.h): a
progress callback sees every stage advance and changes nothing, returning False raises
frepfarm.Cancelled, Ctrl-C (SIGINT) raises KeyboardInterrupt during a search of many seconds,
and the module works normally afterwards."""
import os
import signal
import subprocess
import sys
import textwrap

import pytest

import frepfarm

SPHERE = "my_model(x[3], a[1]) { my_model = 0.8 - x[1]^2 - x[2]^2 - x[3]^2; }"
# A blobby object summed with a ball by branch-and-bound: a search at every point (frep mesh
# of it at 64^3 takes about 20 s on one core).
SLOW = """blob(x[3], a[1]) {
  array x0[3], y0[3], z0[3], ai[3], bi[3];
  x0 = [-0.8, 0.8, 0]; y0 = [0, 0, 1.0]; z0 = [0, 0, 0];
  ai = [2, 2, 3]; bi = [1, 1, 0.8];
  blob = hfBlobby(x, x0, y0, z0, ai, bi, 0.4);
}
ball(x[3], a[1]) { array c[3]; c = [0, 0, 0]; ball = hfSphere(x, c, 0.3); }
my_model(x[3], a[1]) { my_model = frMinkowski(x, blob, ball); }
"""
BOX = ([-1.5, -1.5, -1.5], [1.5, 1.5, 1.5])


def test_progress_reports_every_stage_and_changes_nothing():
    m = frepfarm.compile(SPHERE)
    seen = []
    plain = m.mesh(*BOX, res=48, simplify=0.2)
    watched = m.mesh(*BOX, res=48, simplify=0.2, progress=lambda *r: seen.append(r))
    assert (plain.vertices == watched.vertices).all()
    assert (plain.triangles == watched.triangles).all()
    # The callback gets the latest report every 50 ms and once at the end (the last stage's).
    assert seen and {stage for stage, _, _ in seen} <= {"sample", "mesh", "simplify"}
    assert seen[-1][0] == "simplify"
    for stage, done, total in seen:
        assert 0 <= done <= total
    sampled = []
    v = m.sample(*BOX, res=48, progress=lambda *r: sampled.append(r))
    assert v.inside_volume() == m.sample(*BOX, res=48).inside_volume()
    assert sampled[-1][0] == "sample" and sampled[-1][1] == sampled[-1][2] > 0


def test_progress_returning_false_cancels():
    m = frepfarm.compile(SLOW)
    calls = []

    def stop(stage, done, total):
        calls.append((stage, done, total))
        return False

    with pytest.raises(frepfarm.Cancelled):
        m.mesh(*BOX, res=64, progress=stop)
    assert calls
    # measure keeps its last whole round: valid bounds, stop_reason "cancelled"
    s = frepfarm.compile(SPHERE)
    r = s.measure([-1, -1, -1], [1, 1, 1], tolerance=1e-4, progress=lambda st, d, t: d < 2)
    assert r["stop_reason"] == "cancelled"
    exact = 4.0 / 3.0 * 3.141592653589793 * 0.8 ** 1.5
    assert r["volume"]["lower"] <= exact <= r["volume"]["upper"]


def test_keyboard_interrupt_during_a_search_then_the_module_still_works():
    m = frepfarm.compile(SLOW)

    def ctrl_c(stage, done, total):
        os.kill(os.getpid(), signal.SIGINT)  # as a terminal's Ctrl-C, during the search

    with pytest.raises(KeyboardInterrupt):
        m.mesh(*BOX, res=64, progress=ctrl_c)
    assert frepfarm.compile(SPHERE).eval([[0.0, 0.0, 0.0]])[0] == pytest.approx(0.8)


def test_sigint_from_outside_ends_a_long_call_with_keyboard_interrupt():
    script = textwrap.dedent(f"""
        import sys, frepfarm
        m = frepfarm.compile({SLOW!r})
        def started(stage, done, total):
            if not started.said:
                print("started", flush=True)
                started.said = True
        started.said = False
        try:
            m.mesh({BOX[0]!r}, {BOX[1]!r}, res=96, progress=started)
        except KeyboardInterrupt:
            print("KeyboardInterrupt", flush=True)
            sys.exit(3)
        print("finished", flush=True)
    """)
    child = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True,
                             env=dict(os.environ))
    try:
        assert child.stdout.readline().strip() == "started"
        child.send_signal(signal.SIGINT)
        out, _ = child.communicate(timeout=60)  # a hang guard: it ends in well under a second
    finally:
        if child.poll() is None:
            child.kill()
            child.wait()
    assert out.strip() == "KeyboardInterrupt"
    assert child.returncode == 3
