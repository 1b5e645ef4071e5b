"""Result files a rock engineer opens: VTK XML particle files (.vtu, ParaView), CSV curves, PNG plots,
and the `summary.json` every reference script writes."""
import base64
import csv
import json
import os

import numpy as np

from .scene import SYM_NAMES, dim_of, get, id_order


def _b64(arr):
    raw = np.ascontiguousarray(arr).tobytes()
    return base64.b64encode(np.uint64(len(raw)).tobytes() + raw).decode("ascii")


def write_vtu(path, points, point_data):
    """Unstructured grid of vertices with per-point arrays (1-D: scalar, 2-D: components).
    points: (N, 2|3) [m]. Binary (base64) inline data, UInt64 headers; ParaView reads it directly."""
    points = np.asarray(points, float)
    n = len(points)
    if points.shape[1] == 2:
        points = np.column_stack([points, np.zeros(n)])
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    with open(path, "w") as f:
        f.write('<?xml version="1.0"?>\n<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" '
                'header_type="UInt64">\n<UnstructuredGrid>\n')
        f.write(f'<Piece NumberOfPoints="{n}" NumberOfCells="{n}">\n<PointData>\n')
        for name, a in point_data.items():
            a = np.asarray(a)
            typ = "Int64" if a.dtype.kind in "iu" else "Float64"
            a = a.astype(np.int64 if typ == "Int64" else np.float64)
            nc = 1 if a.ndim == 1 else a.shape[1]
            f.write(f'<DataArray type="{typ}" Name="{name}" NumberOfComponents="{nc}" format="binary">{_b64(a)}</DataArray>\n')
        f.write('</PointData>\n<Points>\n')
        f.write(f'<DataArray type="Float64" NumberOfComponents="3" format="binary">{_b64(points)}</DataArray>\n')
        f.write('</Points>\n<Cells>\n')
        f.write(f'<DataArray type="Int64" Name="connectivity" format="binary">{_b64(np.arange(n, dtype=np.int64))}</DataArray>\n')
        f.write(f'<DataArray type="Int64" Name="offsets" format="binary">{_b64(np.arange(1, n + 1, dtype=np.int64))}</DataArray>\n')
        f.write(f'<DataArray type="UInt8" Name="types" format="binary">{_b64(np.ones(n, dtype=np.uint8))}</DataArray>\n')
        f.write('</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n')


def particle_fields(solver):
    """Every particle field, in particle-id order, as a dict ready for write_vtu."""
    d = dim_of(solver)
    order = id_order(solver)                      # one sort for all fields

    def field(name):
        return get(solver, name, order)

    pos = field("pos")
    fields = {"id": field("id"), "velocity": field("vel"), "mass": field("mass"),
              "volume": field("volume")}
    st = field("stress")
    for k, c in enumerate(SYM_NAMES[d]):
        fields[f"stress_{c}"] = st[:, k]
    fields["max_principal_stress"] = field("max_principal_stress")
    fields["max_tensile_principal_stress"] = np.maximum(fields["max_principal_stress"], 0.0)
    mat_index = field("material").astype(np.int64)
    if solver.numMaterials > 1:
        fields["material"] = mat_index            # index into solver.material(i)
    if 1 in solver.materialKinds:                 # some material is DP–GK
        fields["damage"] = field("damage")
        fields["plastic_strain"] = field("plastic_strain")
        fields["cohesion"] = field("cohesion")
        # crack indicators used by the paper's figures: tensile crack = fully damaged particle,
        # shear crack = plastic strain past the softening end (cohesion at its 0.1 c0 floor), per material
        mats = [solver.material(i) for i in range(solver.numMaterials)]
        end = np.array([(1 - m.residualCohesion) * m.critPlasticStrain if k == 1 else np.inf
                        for m, k in zip(mats, solver.materialKinds)])
        fields["tensile_crack"] = (fields["damage"] >= 1.0).astype(np.int64)
        fields["shear_crack"] = (fields["plastic_strain"] >= end[mat_index]).astype(np.int64)
    return pos, fields


def write_particles(path, solver):
    """All particle fields of a solver to a .vtu file."""
    pos, fields = particle_fields(solver)
    write_vtu(path, pos, fields)


def write_csv(path, header, rows):
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(header)
        for r in rows:
            w.writerow([f"{v:.9g}" if isinstance(v, (float, np.floating)) else v for v in r])


def write_summary(out_dir, summary):
    os.makedirs(out_dir, exist_ok=True)
    def conv(o):
        if isinstance(o, (np.floating, np.integer)):
            return o.item()
        if isinstance(o, np.ndarray):
            return o.tolist()
        raise TypeError(type(o))
    with open(os.path.join(out_dir, "summary.json"), "w") as f:
        json.dump(summary, f, indent=2, default=conv)


def pyplot():
    """matplotlib with a file-only backend."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def write_pvd(path, entries):
    """ParaView collection file indexing a time series: entries = [(time [s], file path), …]; paths are
    written relative to the .pvd's folder. Written to a temporary file and renamed, so a reader (or an
    interrupted run) never sees half an index."""
    folder = os.path.dirname(os.path.abspath(path))
    os.makedirs(folder, exist_ok=True)
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write('<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">\n<Collection>\n')
        for t, p in entries:
            rel = os.path.relpath(os.path.abspath(p), folder)
            f.write(f'<DataSet timestep="{float(t):.12g}" group="" part="0" file="{rel}"/>\n')
        f.write('</Collection>\n</VTKFile>\n')
    os.replace(tmp, path)


class VtuSeries:
    """A VTU time series of the particles with a .pvd index for ParaView: ``write(solver)`` writes
    DIR/NAME_NNNNNNNN.vtu (the solver step) and rewrites DIR/NAME.pvd, so the index always lists
    every file written so far (also after an interrupted run). Use as a runner callback:
    ``runner.run(s, ..., every=[(1e-3, series.write)])``. `fields`: a function solver → (points,
    {name: array}) (default: ``particle_fields``, every particle field)."""

    def __init__(self, directory, name="particles", fields=None):
        if not isinstance(name, str) or not name or os.sep in name:
            raise ValueError(f"name = {name!r} must be a non-empty file name stem")
        self.directory, self.name = directory, name
        self.fields = fields or particle_fields
        self.entries = []
        self.pvd = os.path.join(directory, f"{name}.pvd")

    def write(self, solver):
        """Write the current state; returns the .vtu path. A second write at the same step replaces
        the first (same file, one index entry)."""
        path = os.path.join(self.directory, f"{self.name}_{int(solver.steps):08d}.vtu")
        points, data = self.fields(solver)
        write_vtu(path, points, data)
        self.entries = [e for e in self.entries if e[1] != path] + [(float(solver.time), path)]
        write_pvd(self.pvd, self.entries)
        return path
