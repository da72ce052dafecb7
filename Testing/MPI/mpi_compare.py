"""SDFCage MPI tests: shared checks (the same cage, the same results) for pvbatch and pvpython.

Plain VTK only (no paraview.simple), so that both the pvbatch scripts and the client of the
client-server test use it.
"""
from vtkmodules.vtkCommonDataModel import vtkStaticPointLocator


class Checker:
    def __init__(self):
        self.failures = []

    def check(self, condition, message):
        print(("ok:   " if condition else "FAIL: ") + message, flush=True)
        if not condition:
            self.failures.append(message)

    def finish(self):
        if self.failures:
            print("%d check(s) failed:" % len(self.failures))
            for f in self.failures:
                print("  FAIL: " + f)
            raise SystemExit(1)
        print("all checks passed")


def diagonal(poly):
    b = poly.GetBounds()
    return ((b[1] - b[0]) ** 2 + (b[3] - b[2]) ** 2 + (b[5] - b[4]) ** 2) ** 0.5


def largest_point_offset(a, b):
    """Largest distance from a point of `a` to the nearest point of `b` and back (the two point
    sets' Hausdorff distance), or infinity when either is empty."""
    if a.GetNumberOfPoints() == 0 or b.GetNumberOfPoints() == 0:
        return float("inf")
    worst = 0.0
    for x, y in ((a, b), (b, a)):
        loc = vtkStaticPointLocator()
        loc.SetDataSet(y)
        loc.BuildLocator()
        for i in range(x.GetNumberOfPoints()):
            p = x.GetPoint(i)
            q = y.GetPoint(loc.FindClosestPoint(p))
            d = ((p[0] - q[0]) ** 2 + (p[1] - q[1]) ** 2 + (p[2] - q[2]) ** 2) ** 0.5
            worst = max(worst, d)
    return worst


def field_value(poly, name):
    a = poly.GetFieldData().GetAbstractArray(name)
    if a is None or a.GetNumberOfValues() < 1:
        return None
    return a.GetValue(0)


def same_surface(chk, what, parallel, serial, tolerance=1e-9):
    """The same number of points and triangles, every point within tolerance * diagonal."""
    chk.check(parallel.GetNumberOfPoints() == serial.GetNumberOfPoints(),
              "%s: %d points under MPI, %d serial" % (what, parallel.GetNumberOfPoints(), serial.GetNumberOfPoints()))
    chk.check(parallel.GetNumberOfPolys() == serial.GetNumberOfPolys(),
              "%s: %d triangles under MPI, %d serial" % (what, parallel.GetNumberOfPolys(), serial.GetNumberOfPolys()))
    d = largest_point_offset(parallel, serial)
    chk.check(d <= tolerance * max(diagonal(serial), 1e-300),
              "%s: every point where the serial run has one (largest offset %.3g, diagonal %.3g)"
              % (what, d, diagonal(serial)))


def same_results(chk, what, parallel, serial, names, relative=1e-9):
    """Field-data results equal (numbers within `relative`, texts exactly)."""
    for name in names:
        a, b = field_value(parallel, name), field_value(serial, name)
        if isinstance(b, str) or isinstance(a, str):
            ok = a == b
        elif a is None or b is None:
            ok = False
        else:
            ok = abs(a - b) <= relative * max(abs(a), abs(b), 1e-300)
        chk.check(ok, "%s: %s = %r under MPI, %r serial" % (what, name, a, b))
