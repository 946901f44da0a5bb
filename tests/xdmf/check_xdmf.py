"""Open an empm XDMF file with VTK's XDMF readers (those ParaView uses) and check what they see.

usage: check_xdmf.py READERS FILE.xmf NPOINTS TIME...   (READERS: xdmf2, xdmf3 or xdmf2,xdmf3)
Exit status 77 when the readers are not installed (scripts/setup-deps).

The case (shear.nml) starts from a uniform stress with distinct Voigt components
(xx, yy, zz, yz, xz, xy) = (11, 22, 33, 23, 13, 1000) Pa, so a component in the wrong place
shows. Checked with each reader asked for (vtkXdmfReader: ParaView's "XDMF Reader";
vtkXdmf3Reader: its "Xdmf3 Reader"): the point count and one vertex cell per point, the time
values, every stress component at t = 0 (sigma_xy = 1000 Pa as XY and YX), the fields present,
zero displacement at t = 0 and displacement = x - x0 at the last frame, the material id.
"""
import sys

try:
    from vtkmodules.vtkIOXdmf2 import vtkXdmfReader
    from vtkmodules.vtkIOXdmf3 import vtkXdmf3Reader
    from vtkmodules.vtkCommonDataModel import vtkDataSet
    from vtkmodules.vtkCommonExecutionModel import vtkStreamingDemandDrivenPipeline as SDDP
except ImportError as exc:  # Debian's python3-vtk9 has no XDMF readers; python3-paraview has
    print(f"VTK's XDMF readers are not installed ({exc}): run scripts/setup-deps")
    sys.exit(77)

FAILS = []


def check(cond, what):
    if not cond:
        FAILS.append(what)
        print("FAIL:", what)


def first_block(obj):
    """The dataset of a frame (the readers may wrap it in a multiblock)."""
    if isinstance(obj, vtkDataSet):
        return obj
    it = obj.NewIterator()
    it.InitTraversal()
    return it.GetCurrentDataObject()


def frame(reader, t):
    reader.UpdateTimeStep(t)
    return first_block(reader.GetOutputDataObject(0))


def component(arr, name):
    names = [arr.GetComponentName(c) for c in range(arr.GetNumberOfComponents())]
    return names.index(name) if name in names else None


def run(label, reader, path, npoints, times):
    reader.SetFileName(path)
    reader.UpdateInformation()
    info = reader.GetOutputInformation(0)
    got_times = list(info.Get(SDDP.TIME_STEPS()) or [])
    check(len(got_times) == len(times) and
          all(abs(a - b) <= 1e-12 * max(1.0, abs(b)) for a, b in zip(got_times, times)),
          f"{label}: time values {got_times}, expected {times}")
    ds0 = frame(reader, times[0])
    check(ds0.GetNumberOfPoints() == npoints,
          f"{label}: {ds0.GetNumberOfPoints()} points, expected {npoints}")
    check(ds0.GetNumberOfCells() == npoints,
          f"{label}: {ds0.GetNumberOfCells()} cells, expected one vertex per point ({npoints})")
    pd = ds0.GetPointData()
    for field, ncomp in (("stress", 9), ("strain", 9), ("displacement", 3), ("velocity", 3),
                         ("density", 1), ("volume", 1), ("material", 1)):
        arr = pd.GetArray(field)
        check(arr is not None and arr.GetNumberOfComponents() == ncomp,
              f"{label}: no point array '{field}' with {ncomp} components")
    stress = pd.GetArray("stress")
    if stress is not None:
        # A full tensor, 9 components row by row (ParaView numbers them 0..8): both readers
        # deliver it unchanged, so the row-major position of each component is its name.
        check(stress.GetNumberOfComponents() == 9,
              f"{label}: stress has {stress.GetNumberOfComponents()} components, expected 9")
        order = ["XX", "XY", "XZ", "YX", "YY", "YZ", "ZX", "ZY", "ZZ"]
        expect = {"XX": 11.0, "YY": 22.0, "ZZ": 33.0, "YZ": 23.0, "ZY": 23.0, "XZ": 13.0,
                  "ZX": 13.0, "XY": 1000.0, "YX": 1000.0}
        for name, value in expect.items():
            c = component(stress, name)
            if c is None:
                c = order.index(name)
            got = [stress.GetComponent(p, c) for p in range(stress.GetNumberOfTuples())]
            check(all(g == value for g in got),
                  f"{label}: stress {name} at t = 0 is {got[0]}, expected {value}")
    disp = pd.GetArray("displacement")
    if disp is not None:
        check(all(disp.GetComponent(p, c) == 0.0 for p in range(npoints) for c in range(3)),
              f"{label}: displacement at t = 0 is not zero")
    mat = pd.GetArray("material")
    if mat is not None:
        check(all(mat.GetComponent(p, 0) == 1 for p in range(npoints)),
              f"{label}: material id is not 1")
    x0 = [ds0.GetPoint(p) for p in range(npoints)]
    ds1 = frame(reader, times[-1])
    check(ds1.GetNumberOfPoints() == npoints, f"{label}: last frame point count")
    disp = ds1.GetPointData().GetArray("displacement")
    if disp is not None:
        err = max(abs(ds1.GetPoint(p)[c] - x0[p][c] - disp.GetComponent(p, c))
                  for p in range(npoints) for c in range(3))
        moved = max(abs(disp.GetComponent(p, c)) for p in range(npoints) for c in range(3))
        check(err <= 1e-12 and moved > 0.0,
              f"{label}: last frame displacement != x - x0 (error {err}, largest {moved})")
    print(f"{label}: {npoints} points, times {got_times}")


def main():
    readers = sys.argv[1].split(",")
    path, npoints, times = sys.argv[2], int(sys.argv[3]), [float(t) for t in sys.argv[4:]]
    if "xdmf2" in readers:
        run(f"XDMF2 reader, {path}", vtkXdmfReader(), path, npoints, times)
    if "xdmf3" in readers:
        run(f"Xdmf3 reader, {path}", vtkXdmf3Reader(), path, npoints, times)
    if FAILS:
        sys.exit(1)


main()
