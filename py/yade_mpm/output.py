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
    if solver.materialKind == 1:
        fields["damage"] = field("damage")
        fields["plastic_strain"] = field("plastic_strain")
        fields["cohesion"] = field("cohesion")
        # crack indicators used by the paper's figures: tensile crack = fully damaged particle,
        # shear crack = plastic strain past the softening end (cohesion at its 0.1 c0 floor)
        m = solver.dpgkParameters()
        fields["tensile_crack"] = (fields["damage"] >= 1.0).astype(np.int64)
        fields["shear_crack"] = (fields["plastic_strain"] >= (1 - m.residualCohesion) * m.critPlasticStrain).astype(np.int64)
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
