# Opens tomorig XDMF sidecars in ParaView's three XDMF readers and checks every array of every
# grid against the HDF5 values read by h5dump (the reference outside ParaView and tomorig).
# Run by xdmf_paraview_test.sh with pvpython; usage:
#   pvpython check_xdmf.py results r.xdmf r.h5 [volume v.xdmf v.h5 ...]
import os
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET

import numpy as np
from paraview import servermanager
from paraview.simple import OpenDataFile, XDMFReader, Xdmf3ReaderS, Xdmf3ReaderT
from vtk.numpy_interface import dataset_adapter as dsa

failures = []


def fail(message):
    failures.append(message)
    print("FAIL: " + message, flush=True)


def h5dump_array(h5_path, dataset, start=None, count=None, dtype=np.float32):
    """A dataset (or a hyperslab of it) as raw little-endian values, read by h5dump."""
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "raw.bin")
        command = ["h5dump", "-d", dataset]
        if start is not None:
            command += ["-s", ",".join(map(str, start)), "-c", ",".join(map(str, count))]
        command += ["-b", "LE", "-o", out, h5_path]
        subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
        return np.fromfile(out, dtype=dtype)


def h5dump_dims(h5_path, dataset):
    header = subprocess.run(["h5dump", "-H", "-d", dataset, h5_path], check=True, capture_output=True,
                            text=True).stdout
    inside = header.split("DATASPACE")[1].split("(")[1].split(")")[0]
    return [int(n) for n in inside.split(",")]


def blocks(output):
    """Every leaf data set of a reader's output (composite or not) with its block name."""
    if output is None:
        return []
    if not output.IsA("vtkCompositeDataSet"):
        return [("", output)]
    found = []
    it = output.NewIterator()
    it.InitTraversal()
    while not it.IsDoneWithTraversal():
        meta = it.GetCurrentMetaData() if it.HasCurrentMetaData() else None
        name = meta.Get(output.NAME()) if meta is not None and meta.Has(output.NAME()) else ""
        found.append((name, it.GetCurrentDataObject()))
        it.GoToNextItem()
    return found


def fetch(reader, time=None):
    if time is None:
        reader.UpdatePipeline()
    else:
        reader.UpdatePipeline(time)
    return servermanager.Fetch(reader)


def expect_array(label, data, name, expected):
    array = data.GetPointData().GetArray(name)
    if array is None:
        fail("%s: no array '%s' (arrays: %s)" % (label, name, [data.GetPointData().GetArrayName(i) for i in
                                                             range(data.GetPointData().GetNumberOfArrays())]))
        return
    values = np.asarray(dsa.vtkDataArrayToVTKArray(array)).astype(np.float64).ravel()
    if values.size != expected.size:
        fail("%s: '%s' has %d values, HDF5 has %d" % (label, name, values.size, expected.size))
        return
    worst = float(np.max(np.abs(values - expected))) if values.size else 0.0
    if not np.allclose(values, expected, rtol=0, atol=1e-6, equal_nan=True):
        fail("%s: '%s' differs from HDF5 by up to %g" % (label, name, worst))
    else:
        print("ok: %s: '%s' (%d values) matches h5dump" % (label, name, values.size), flush=True)


def time_steps(xdmf):
    root = ET.parse(xdmf).getroot()
    return [float(t.get("Value")) for t in root.iter("Time")]


def check_results(xdmf, h5):
    # The expected value of every set, from /sets/set_index and the velocity rows (h5dump).
    rows = h5dump_dims(h5, "/sets/velocity_m_s")
    set_index = h5dump_array(h5, "/sets/set_index", dtype=np.uint64)
    complete = h5dump_array(h5, "/sets/complete", dtype=np.uint8)
    finished = [r for r in range(min(rows[0], len(set_index), len(complete))) if complete[r] == 1]
    by_set = {}
    for r in finished:  # a later row of the same set wins (docs/file-formats.md)
        by_set[int(set_index[r])] = r
    expected = []
    for s in sorted(by_set):
        r = by_set[s]
        expected.append((s, h5dump_array(h5, "/sets/velocity_m_s", [r, 0, 0, 0, 0], [1] + rows[1:]).astype(np.float64),
                         h5dump_array(h5, "/sets/status", [r, 0, 0, 0], [1] + rows[1:4], np.uint8).astype(np.float64)))
    if len(expected) < 2:
        fail("%s: the test needs at least two finished sets, has %d" % (h5, len(expected)))
    mean = h5dump_array(h5, "/statistics/mean_velocity_m_s", dtype=np.float64).astype(np.float64)
    times = time_steps(xdmf)
    if len(times) != len(expected):
        fail("%s: %d time steps for %d finished sets" % (xdmf, len(times), len(expected)))

    # Every reader: one time step per set, whose block holds the set's arrays and the statistics.
    for reader_name, make in (("XDMFReader", XDMFReader), ("Xdmf3ReaderS", Xdmf3ReaderS),
                              ("Xdmf3ReaderT", Xdmf3ReaderT)):
        reader = make(FileName=xdmf) if reader_name != "XDMFReader" else make(FileNames=xdmf)
        reader.UpdatePipelineInformation()
        reader_times = list(reader.TimestepValues) if reader.TimestepValues else []
        if len(reader_times) != len(expected):
            fail("%s: %d time steps, expected %d" % (reader_name, len(reader_times), len(expected)))
            continue
        for (s, velocity, status), t in zip(expected, reader_times):
            found = [(n, d) for n, d in blocks(fetch(reader, t)) if d.GetPointData().GetNumberOfArrays() > 0]
            if len(found) != 1:
                fail("%s t=%g (set %d): %d blocks with arrays, expected 1" % (reader_name, t, s, len(found)))
                continue
            label = "%s set %d" % (reader_name, s)
            expect_array(label, found[0][1], "velocity_m_s", velocity)
            expect_array(label, found[0][1], "status", status)
            expect_array(label, found[0][1], "mean_velocity_m_s", mean)


def check_volume(xdmf, h5):
    names = [g.get("Name") for g in ET.parse(xdmf).getroot().iter("Grid")]
    if not names:
        fail("%s: no grid" % xdmf)
    for reader_name, make in (("XDMFReader", XDMFReader), ("Xdmf3ReaderS", Xdmf3ReaderS),
                              ("Xdmf3ReaderT", Xdmf3ReaderT)):
        reader = make(FileName=xdmf) if reader_name != "XDMFReader" else make(FileNames=xdmf)
        found = [(n, d) for n, d in blocks(fetch(reader)) if d.GetPointData().GetArray("intensity")]
        if len(found) != len(names):
            fail("%s: %d grids with 'intensity', the sidecar has %d" % (reader_name, len(found), len(names)))
            continue
        for name, (_, data) in zip(names, found):
            expect_array("%s volume %s" % (reader_name, name), data, "intensity",
                         h5dump_array(h5, "/volumes/%s/dense" % name).astype(np.float64))


arguments = sys.argv[1:]
if not arguments or len(arguments) % 3:
    sys.exit("usage: pvpython check_xdmf.py results|volume FILE.xdmf FILE.h5 [...]")
for i in range(0, len(arguments), 3):
    kind, xdmf, h5 = arguments[i], os.path.abspath(arguments[i + 1]), os.path.abspath(arguments[i + 2])
    (check_results if kind == "results" else check_volume)(xdmf, h5)
if failures:
    print("%d check(s) failed" % len(failures))
    sys.exit(1)
print("all checks passed")
