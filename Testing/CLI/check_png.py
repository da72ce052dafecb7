"""Checks that a screenshot is a real picture: a readable PNG of a reasonable size with many
colours (not a blank or single-colour image). Usage: python3 check_png.py FILE.png

Uses VTK's PNG reader from the same VTK the project builds against (ParaView's, under
/usr/bin/python3), so no extra Python package is needed.
"""
import os
import sys

from vtkmodules.vtkIOImage import vtkPNGReader


def main(path):
    if not os.path.isfile(path):
        print(f"FAIL: {path} does not exist")
        return 1
    size = os.path.getsize(path)
    reader = vtkPNGReader()
    if not reader.CanReadFile(path):
        print(f"FAIL: {path} is not a PNG file")
        return 1
    reader.SetFileName(path)
    reader.Update()
    image = reader.GetOutput()
    width, height, _ = image.GetDimensions()
    scalars = image.GetPointData().GetScalars()
    if scalars is None or width < 200 or height < 200:
        print(f"FAIL: {path} is {width}x{height} without pixels")
        return 1
    components = scalars.GetNumberOfComponents()
    n = scalars.GetNumberOfTuples()
    step = max(1, n // 20000)
    colours = set()
    drawn = 0
    samples = 0
    for i in range(0, n, step):
        rgb = tuple(int(c) for c in scalars.GetTuple(i)[:3])
        colours.add(rgb)
        # the background is a vertical gradient: the left pixel of a row shows its colour
        row_start = tuple(int(c) for c in scalars.GetTuple((i // width) * width)[:3])
        if max(abs(a - b) for a, b in zip(rgb, row_start)) > 10:
            drawn += 1
        samples += 1
    fraction = drawn / samples
    print(f"{path}: {size} bytes, {width}x{height}x{components}, "
          f"{len(colours)} distinct colours and {100 * fraction:.1f}% non-background pixels "
          f"in {samples} samples")
    if size < 10000:
        print("FAIL: the file is suspiciously small")
        return 1
    if len(colours) < 50:
        print("FAIL: too few colours: blank or single-colour image")
        return 1
    if fraction < 0.05:
        print("FAIL: almost everything is background: the meshes were not drawn")
        return 1
    print("OK")
    return 0


if __name__ == "__main__":
    if len(sys.argv) != 2:
        print(__doc__)
        sys.exit(2)
    sys.exit(main(sys.argv[1]))
