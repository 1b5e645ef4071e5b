"""Result files a rock engineer opens: VTK XML particle files (.vtu, ParaView), CSV curves, PNG plots,
and the `summary.json` every reference script writes."""
import base64
import csv
import json
import os

import numpy as np

from .fields import SYM_NAMES, dim_of, get, id_order


def _b64(arr):
    raw = np.ascontiguousarray(arr).tobytes()
    return base64.b64encode(np.uint64(len(raw)).tobytes() + raw).decode("ascii")


def _layout(a):
    """VTK type name and component count of a point-data array (as write_vtu writes it)."""
    a = np.asarray(a)
    return ("Int64" if a.dtype.kind in "iu" else "Float64"), (1 if a.ndim == 1 else a.shape[1])


def write_pvtu(path, pieces, point_data):
    """Parallel VTU index (ParaView): the piece files (one .vtu per MPI rank, written by write_vtu) and
    the layout of their point arrays (`point_data`: one rank's dict; every piece has the same arrays)."""
    folder = os.path.dirname(os.path.abspath(path))
    os.makedirs(folder, exist_ok=True)
    with open(path, "w") as f:
        f.write('<?xml version="1.0"?>\n<VTKFile type="PUnstructuredGrid" version="1.0" byte_order="LittleEndian" '
                'header_type="UInt64">\n<PUnstructuredGrid GhostLevel="0">\n<PPointData>\n')
        for name, a in point_data.items():
            typ, nc = _layout(a)
            f.write(f'<PDataArray type="{typ}" Name="{name}" NumberOfComponents="{nc}"/>\n')
        f.write('</PPointData>\n<PPoints>\n<PDataArray type="Float64" NumberOfComponents="3"/>\n</PPoints>\n')
        for p in pieces:
            f.write(f'<Piece Source="{os.path.relpath(os.path.abspath(p), folder)}"/>\n')
        f.write('</PUnstructuredGrid>\n</VTKFile>\n')


def write_particle_file(stem, points, data):
    """STEM.vtu, or under MPI (N > 1 ranks) this rank's piece STEM.rK.vtu and, from rank 0, the index
    STEM.pvtu of all N pieces (doc/developer/scaling.md). Returns the path to open (.vtu or .pvtu)."""
    from .parallel import rank, size
    if size() == 1:
        write_vtu(stem + ".vtu", points, data)
        return stem + ".vtu"
    write_vtu(f"{stem}.r{rank()}.vtu", points, data)
    if rank() == 0:
        write_pvtu(stem + ".pvtu", [f"{stem}.r{k}.vtu" for k in range(size())], data)
    return stem + ".pvtu"


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
            typ, nc = _layout(a)
            a = np.asarray(a).astype(np.int64 if typ == "Int64" else np.float64)
            f.write(f'<DataArray type="{typ}" Name="{name}" NumberOfComponents="{nc}" format="binary">{_b64(a)}</DataArray>\n')
        f.write('</PointData>\n<Points>\n')
        f.write(f'<DataArray type="Float64" NumberOfComponents="3" format="binary">{_b64(points)}</DataArray>\n')
        f.write('</Points>\n<Cells>\n')
        f.write(f'<DataArray type="Int64" Name="connectivity" format="binary">{_b64(np.arange(n, dtype=np.int64))}</DataArray>\n')
        f.write(f'<DataArray type="Int64" Name="offsets" format="binary">{_b64(np.arange(1, n + 1, dtype=np.int64))}</DataArray>\n')
        f.write(f'<DataArray type="UInt8" Name="types" format="binary">{_b64(np.ones(n, dtype=np.uint8))}</DataArray>\n')
        f.write('</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n')


def particle_fields(solver, x0=None):
    """Every particle field, in particle-id order, as a dict ready for write_vtu; with the initial
    positions x0 (by id) also the displacement."""
    d = dim_of(solver)
    order = id_order(solver)                      # one sort for all fields

    def field(name):
        return get(solver, name, order)

    pos = field("pos")
    fields = {"id": field("id"), "velocity": field("vel"), "mass": field("mass"),
              "volume": field("volume")}
    if x0 is not None:
        fields["displacement"] = pos - x0
    st = field("stress")
    for k, c in enumerate(SYM_NAMES[d]):
        fields[f"stress_{c}"] = st[:, k]
    fields["max_principal_stress"] = field("max_principal_stress")
    fields["max_tensile_principal_stress"] = np.maximum(fields["max_principal_stress"], 0.0)
    if solver.numMaterials > 1:
        fields["material"] = field("material").astype(np.int64)   # index into solver.material(i)
    if 1 in solver._materialKinds:                 # some material is DP–GK
        from .analysis import softening_end
        fields["damage"] = field("damage")
        fields["plastic_strain"] = field("plastic_strain")
        fields["cohesion"] = field("cohesion")
        # crack indicators used by the paper's figures: tensile crack = fully damaged particle,
        # shear crack = plastic strain past the softening end (cohesion at its 0.1 c0 floor), per material
        fields["tensile_crack"] = (fields["damage"] >= 1.0).astype(np.int64)
        fields["shear_crack"] = (fields["plastic_strain"] >= softening_end(solver, order)).astype(np.int64)
    gone = field("removed")
    if gone.any():                                # particles removed after leaving the grid are left out
        keep = ~gone
        pos, fields = pos[keep], {k: v[keep] for k, v in fields.items()}
    return pos, fields


def write_particles(path, solver):
    """All particle fields of a solver to a .vtu file (under MPI: this rank's piece and a .pvtu index with the
    same stem, write_particle_file). Returns the path written (.vtu or .pvtu)."""
    pos, fields = particle_fields(solver)
    return write_particle_file(os.path.splitext(path)[0] if path.endswith(".vtu") else path, pos, fields)


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


def read_pvd(path):
    """(time [s], file path) entries of an existing .pvd ([] if there is none)."""
    import re
    if not os.path.exists(path):
        return []
    d = os.path.dirname(path)
    with open(path) as f:
        return [(float(t), os.path.join(d, n)) for t, n in re.findall(r'timestep="([^"]+)"[^>]*file="([^"]+)"', f.read())]


class VtuSeries:
    """A VTU time series of the particles with a .pvd index for ParaView: ``write(solver)`` writes
    DIR/NAME_NNNNNNNN.vtu (the solver step; under MPI one piece per rank and a .pvtu) and rewrites DIR/NAME.pvd, so the index always lists
    every file written so far (also after an interrupted run). Use as a runner callback:
    ``runner.run(s, ..., every=[(1e-3, series.write)])``. `fields`: a function solver → (points,
    {name: array}) (default: ``particle_fields``, every particle field)."""

    def __init__(self, directory, name="particles", fields=None, resume=False):
        """resume=True continues the index of an existing DIR/NAME.pvd (a resumed run keeps the files
        written before its interruption)."""
        if not isinstance(name, str) or not name or os.sep in name:
            raise ValueError(f"name = {name!r} must be a non-empty file name stem")
        self.directory, self.name = directory, name
        self.fields = fields or particle_fields
        self.pvd = os.path.join(directory, f"{name}.pvd")
        self.entries = read_pvd(self.pvd) if resume else []

    def write(self, solver):
        """Write the current state; returns the .vtu path. A second write at the same step replaces
        the first (same file, one index entry)."""
        from .parallel import rank
        points, data = self.fields(solver)
        path = write_particle_file(os.path.join(self.directory, f"{self.name}_{int(solver.steps):08d}"), points, data)
        self.entries = [e for e in self.entries if e[1] != path] + [(float(solver.time), path)]
        if rank() == 0:   # under MPI one index (.pvd of the .pvtu files) for all ranks
            write_pvd(self.pvd, self.entries)
        return path


# ------------------------------------------------------------------------------------- curves and figures
class CurveRecorder:
    """A load–displacement curve recorded as a runner callback: ``record(solver)`` after every step adds
    y() to a running mean and appends [time, x, mean y] each time x() passes the next multiple of dx
    (e.g. the mean platen stress over every 0.01 mm of platen travel). ``state`` (curve, acc) is a
    JSON-able dict: keep it in a checkpoint's extra state to continue the curve after a resume."""

    def __init__(self, x, y, dx, state=None):
        if not (callable(x) and callable(y)) or not (np.isfinite(dx) and dx > 0):
            raise ValueError(f"CurveRecorder needs callables x(), y() and dx > 0 (got dx = {dx!r})")
        self.x, self.y, self.dx = x, y, float(dx)
        self.state = state if state is not None else {}
        self.state.setdefault("curve", [])
        self.state.setdefault("acc", [0.0, 0])

    def record(self, solver):
        acc = self.state["acc"]
        acc[0] += self.y()
        acc[1] += 1
        x = self.x()
        if x >= len(self.state["curve"]) * self.dx - 1e-12:
            self.state["curve"].append([solver.time, x, acc[0] / acc[1]])
            self.state["acc"] = [0.0, 0]


def sample_curve(x, y, step):
    """[(x_k, y(x_k))] at x_k = 0, step, 2·step … up to the last x (linear interpolation; x increasing)."""
    if len(x) == 0:
        return []
    n = int(np.floor(x[-1] / step + 1e-9)) + 1
    return [(round(k * step, 10), float(np.interp(round(k * step, 10), x, y))) for k in range(n)]


def field_figure(pos, panels, marker_size, xlim=None, ylim=None, ncols=3, panel_size=(5.0, 5.2), unit="m"):
    """Particle fields side by side: panels = [(title, values per particle, colormap, limits)], limits
    (lo, hi), "sym" (symmetric about 0) or None (the data range); pos (N, 2) in `unit`. Axes left
    over in the last row are switched off (room for text). Returns (figure, list of axes)."""
    from matplotlib.colors import Normalize
    plt = pyplot()
    nrows = -(-len(panels) // ncols)
    fig, axs = plt.subplots(nrows, ncols, figsize=(panel_size[0] * ncols, panel_size[1] * nrows))
    axs = list(np.ravel(axs))
    for ax, (title, v, cmap, lim) in zip(axs, panels):
        v = np.asarray(v, float)
        if lim == "sym":
            m = np.max(np.abs(v)) or 1.0
            norm = Normalize(-m, m)
        elif lim is None:
            norm = Normalize(np.min(v), np.max(v) if np.max(v) > np.min(v) else np.min(v) + 1)
        else:
            norm = Normalize(*lim)
        sc = ax.scatter(pos[:, 0], pos[:, 1], c=v, s=marker_size, cmap=cmap, norm=norm, marker="s", linewidths=0, rasterized=True)
        ax.set_title(title, fontsize=9)
        ax.set_aspect("equal")
        ax.set_xlabel(f"x [{unit}]"), ax.set_ylabel(f"y [{unit}]")
        if xlim is not None:
            ax.set_xlim(*xlim)
        if ylim is not None:
            ax.set_ylim(*ylim)
        fig.colorbar(sc, ax=ax, shrink=0.8)
    for ax in axs[len(panels):]:
        ax.axis("off")
    return fig, axs


def box_outline(body):
    """Corners (4, 2) [m] of a YADE Box body's outline in the x–y plane (its current position and
    orientation), for pictures of 2D scenes."""
    e, q, c = body.shape.extents, body.state.ori, body.state.pos
    R = np.array([[q.toRotationMatrix()[i, j] for j in range(2)] for i in range(2)])
    return np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]]) * [e[0], e[1]] @ R.T + [c[0], c[1]]


def scene_figure(x, groups, outlines=(), marker_size=1.0, unit="m", figsize=(4.6, 4.8)):
    """The scene as built: particles at x (N, 2) [unit] drawn as squares, one colour per group
    (groups = [(mask, colour, label)], empty groups skipped) and rigid bodies as filled outlines
    (outlines = [(corners (M, 2) [unit], colour, label)], e.g. ``box_outline``). Returns (figure, axes)."""
    from matplotlib.patches import Polygon as Patch
    plt = pyplot()
    fig, ax = plt.subplots(figsize=figsize)
    for m, color, label in groups:
        if np.any(m):
            ax.scatter(x[m, 0], x[m, 1], s=marker_size, c=color, marker="s", linewidths=0, label=label, rasterized=True)
    for corners, color, label in outlines:
        ax.add_patch(Patch(corners, closed=True, fc=color, alpha=0.6, label=label))
    ax.set_aspect("equal")
    ax.set_xlabel(f"x [{unit}]"), ax.set_ylabel(f"y [{unit}]")
    return fig, ax


def save_figure(fig, path, dpi=110):
    """tight_layout, write `path`, close the figure."""
    fig.tight_layout()
    fig.savefig(path, dpi=dpi)
    pyplot().close(fig)
