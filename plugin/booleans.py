"""Booleans and trims as selections of split pieces (002 §1).

:func:`select_pieces` (:meth:`.split.SplitResult.select`, and through it
:func:`.split.boolean`, :func:`.split.boolean_all` and :func:`.split.trim`) keeps
pieces of a split of two operands: each piece
is classified against the other operand in the math layer
(:func:`~surfprep.algorithms.containment.piece_states`, ray parity on the exact
trimmed surfaces, or the side of the sheet by its normal), the pieces of one region
(:meth:`~surfprep.algorithms.nonmanifold.NonManifoldModel.regions`) must agree, and
the kept faces are built from the split's structure sharing its edges
(:func:`~.occ.structure.structure_to_occ`), a closed shell made a solid.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING, Any

import numpy as np

from ..algorithms.containment import interior_point, piece_states, sheet_side
from ..errors import OpenCascadeError
from .io import named_model
from .occ.shapes import compound, is_valid, sew, shell_or_solid
from .occ.structure import structure_to_occ

if TYPE_CHECKING:
    from .split import SplitResult

__all__ = ["OPERATIONS", "BooleanResult", "select_pieces"]


#: the operations and, per operand, the states of the pieces they keep (of a, of b): "in" or
#: "out" of the other solid, or on its boundary, "shared" (the normals agree: one copy,
#: a's, is kept) or "opposite" (two solids touching there); "cut" turns b's pieces over
OPERATIONS = {"fuse": (("out", "shared"), ("out",)), "common": (("in", "shared"), ("in",)),
              "cut": (("out", "opposite"), ("in",))}


@dataclass(frozen=True, eq=False)
class BooleanResult:
    """A Boolean of two solids as a selection of split pieces (002 §1).

    Attributes
    ----------
    shape : TopoDS_Shape
        The kept pieces built sharing the split's edges (a solid when they close).
    operation : str
    split : SplitResult
    kept : (int, int)
        Pieces of ``a`` and of ``b`` kept.
    closed : bool
        The kept pieces close into solids.
    valid : bool
    """

    shape: Any
    operation: str
    split: SplitResult
    kept: tuple[int, int]
    closed: bool
    valid: bool
    #: the kept faces as built and their names (:meth:`SplitResult.names`)
    named: tuple = field(default=(), repr=False)
    #: for :func:`boolean_all`, the results of the steps before this one, in order
    steps: tuple = field(default=(), repr=False)

    @property
    def geometry(self) -> Any:
        return self.shape

    def as_model(self):
        """``shape`` as a :class:`~surfprep.plugin.io.CadModel` whose faces carry the
        split's names (:meth:`SplitResult.names`)."""
        return named_model(self.shape, [f for f, _ in self.named], [n for _, n in self.named])

    @cached_property
    def volume(self) -> float | None:
        """Of ``shape`` when it is closed, else None: OpenCascade's GProp at 1e-9 (its
        default is 0.1 % off), computed on first use."""
        if not self.closed:
            return None
        from OCP.BRepGProp import BRepGProp
        from OCP.GProp import GProp_GProps
        total = 0.0
        for solid in _solids(self.shape):
            props = GProp_GProps()
            BRepGProp.VolumeProperties_s(solid, props, 1e-9)
            total += abs(float(props.Mass()))
        return total

    def report(self) -> dict:
        return {"operation": self.operation, "kept_pieces_a": self.kept[0], "kept_pieces_b": self.kept[1],
                "volume": self.volume, "valid": self.valid, "split": self.split.report(),
                **({"steps": [{"volume": step.volume, "valid": step.valid, "time_s": step.split.time_s,
                               "kept_pieces_a": step.kept[0], "kept_pieces_b": step.kept[1]}
                              for step in (*self.steps, self)]} if self.steps else {})}


def _solid_of(model, tol: float):
    """The model's solid: the one it holds, else its faces sewn (OpenCascadeError if open)."""
    from OCP.TopAbs import TopAbs_SOLID
    from OCP.TopExp import TopExp_Explorer
    explorer = TopExp_Explorer(model.shape, TopAbs_SOLID)
    if explorer.More():
        return explorer.Current()
    shape, _ = sew(list(model.faces), tol)
    if shape.ShapeType() != TopAbs_SOLID:
        raise OpenCascadeError("a Boolean needs closed solids: the operand's faces do not sew closed")
    return shape


def select_pieces(cut: SplitResult, operation: str, *, keep: str = "front") -> BooleanResult:
    """:meth:`SplitResult.select`: the pieces of ``cut`` a Boolean (``"fuse"``, ``"cut"``,
    ``"common"``) or a trim (``"trim"``, ``keep`` ``"front"`` or ``"back"``) keeps.

    Raises
    ------
    InvalidGeometryError
        A split of one operand, an unknown operation.
    OpenCascadeError
        A face the split could not cut, or a region of pieces on both sides of the other
        operand (a curve is missing).
    """
    from ..errors import InvalidGeometryError
    if len(cut.operands) != 2 or cut.operands[1] is None:
        raise InvalidGeometryError(f"{operation} needs the split of two operands, a and b")
    if operation == "trim":
        return _trimmed(cut, keep)
    if operation not in OPERATIONS:
        raise InvalidGeometryError(f"unknown operation {operation!r}; expected one of "
                                   f"{', '.join(OPERATIONS)} or trim")
    return _selected(cut, operation)


def _selected(cut: SplitResult, operation: str) -> BooleanResult:
    """:meth:`SplitResult.select` of a Boolean (the docstring of :func:`.split.boolean`)."""
    model_a, model_b = cut.operands
    sew_tol = cut.sew_tol
    _solid_of(model_a, sew_tol), _solid_of(model_b, sew_tol)          # both must close
    _all_cut(cut, operation)
    shell_a, shell_b = cut.faces_of(0), cut.faces_of(1)
    # every piece classified, and the pieces of one region (joined by edges the other
    # operand does not use: 002 §1) must agree -- else a curve where they cross the other
    # solid is missing (a tangential contact the intersection did not find)
    structure = cut.structure
    states = piece_states(structure.faces,
                          [shell_b if o[0] == "a" else shell_a for o in structure.origins], tol=sew_tol)
    for region in structure.regions():
        # a piece whose inner point lies on the other solid's boundary but which shares
        # its region with pieces inside or outside it only touches it there (a ball
        # resting on a box's face, at the point in the middle): it is where they are
        found = sorted({states[k] for k in region} - {"shared", "opposite"})
        if len(found) == 1:
            for k in region:
                states[k] = found[0]
        elif len(found) > 1:
            names = cut.names()
            raise OpenCascadeError(
                f"{operation}: the pieces of one region of {structure.origins[region[0]][0]} lie "
                f"{' and '.join(found)} the other solid ({', '.join(str(names[k] or k) for k in region[:4])}"
                f"{'...' if len(region) > 4 else ''}): a curve where it crosses or touches the other "
                "solid is missing; no result rather than a wrong one")
    n_a = len(cut.pieces_a)
    keep_a, keep_b = OPERATIONS[operation]
    chosen_a = [k for k, s in enumerate(states[:n_a]) if s in keep_a]
    chosen_b = [n_a + k for k, s in enumerate(states[n_a:]) if s in keep_b]
    if not chosen_a + chosen_b:
        return BooleanResult(compound([]), operation, cut, (0, 0), True, True)
    # "cut" turns b's pieces over
    shape, named = _assembled(cut, chosen_a + chosen_b, chosen_b if operation == "cut" else [])
    solids = _solids(shape)
    if solids:
        shape = solids[0] if len(solids) == 1 else compound(solids)
    return BooleanResult(shape, operation, cut, (len(chosen_a), len(chosen_b)), bool(solids),
                         is_valid(shape), named)


def _all_cut(cut: SplitResult, operation: str) -> None:
    """Refuse a selection when a face could not be cut: its pieces' sides are then not
    what the selection would keep (a face kept whole is inside and outside at once)."""
    refused = [f for f in cut.faces if f.kept is not None]
    if refused:
        f = refused[0]
        raise OpenCascadeError(f"{operation}: face {f.operand}{f.index} could not be cut along its "
                               f"{f.cuts} curve(s) ({f.kept})" + (f" nor {len(refused) - 1} other face(s)"
                                                                  if len(refused) > 1 else "")
                               + "; no result rather than a wrong one")


def _assembled(cut: SplitResult, chosen: list[int], turned: list[int]) -> tuple[Any, tuple]:
    """The faces ``chosen`` (indices into ``cut.structure.faces``; those in ``turned``
    turned over) in a shell per connected component (a compound of them when more
    than one), built from the structure as :func:`.split.split` builds its
    shape; when the split itself had to be sewn, or a face built so is invalid, the
    split's faces sewn (OpenCascade's manifold sewing loses the seam halves of a cap
    cut across a sphere's seam: every edge came out degenerated, so non-manifold).
    Returns the shape and the faces built with their names."""
    names = cut.names()
    if cut.assembled == "structure":
        try:
            built = structure_to_occ(cut.structure, chosen, turned=turned, tol=cut.sew_tol)
        except OpenCascadeError:
            built = None
        if built is not None and built.valid:
            shape = built.shells[0] if len(built.shells) == 1 else compound(list(built.shells))
            return shape, tuple(zip(built.faces, (names[k] for k in chosen)))
    pieces = cut.pieces_a + cut.pieces_b
    faces = [pieces[k].Reversed() if k in turned else pieces[k] for k in chosen]
    shape = sew(faces, cut.sew_tol, non_manifold=True)[0] if len(faces) > 1 else compound(faces)
    return shape, tuple(zip(faces, (names[k] for k in chosen)))


def _trimmed(cut: SplitResult, keep: str) -> BooleanResult:
    """:meth:`SplitResult.select` of ``"trim"`` (the docstring of :func:`.split.trim`)."""
    from ..errors import InvalidGeometryError
    if keep not in ("front", "back"):
        raise InvalidGeometryError(f"keep must be 'front' or 'back', got {keep!r}")
    _all_cut(cut, f"trim-{keep}")
    sew_tol = cut.sew_tol
    faces_a = cut.structure.faces[:len(cut.pieces_a)]
    points = np.array([interior_point(face)[1] for face in faces_a]).reshape(-1, 3)
    side = sheet_side(cut.faces_of(1), points, tol=sew_tol)
    want = 1 if keep == "front" else -1
    chosen = [k for k, s in enumerate(side) if s == want]
    if not chosen:
        return BooleanResult(compound([]), f"trim-{keep}", cut, (0, 0), False, True)
    shape, named = _assembled(cut, chosen, [])
    solids = _solids(shape)
    if solids:
        shape = solids[0] if len(solids) == 1 else compound(solids)
    return BooleanResult(shape, f"trim-{keep}", cut, (len(chosen), 0), bool(solids), is_valid(shape), named)


def _solids(shape) -> list:
    """The solids of an assembled result: itself, or each closed shell of it made a solid;
    empty when a shell stays open. A closed shell is made a solid as it is (oriented
    by ``BRepLib::OrientClosedSolid``, its faces unchanged so they keep their names),
    else through ShapeFix (:func:`shell_or_solid`)."""
    from OCP.TopAbs import TopAbs_FACE, TopAbs_SHELL, TopAbs_SOLID
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS
    if shape.ShapeType() == TopAbs_SOLID:
        return [shape]
    if shape.ShapeType() == TopAbs_FACE:          # one closed face kept: a ball inside
        solid = shell_or_solid(shape)
        return [solid] if solid.ShapeType() == TopAbs_SOLID else []
    out = []
    explorer = TopExp_Explorer(shape, TopAbs_SHELL)
    while explorer.More():
        shell = TopoDS.Shell_s(explorer.Current())
        explorer.Next()
        solid = _solid_as_it_is(shell)
        if solid is None:
            solid = shell_or_solid(shell)
        if solid.ShapeType() != TopAbs_SOLID:
            return []
        out.append(solid)
    return out


def _solid_as_it_is(shell):
    """A solid of the closed ``shell``, oriented, its faces the shell's; None when the
    shell is open or the solid is not valid."""
    from OCP.BRep import BRep_Builder, BRep_Tool
    from OCP.BRepLib import BRepLib
    from OCP.TopoDS import TopoDS_Solid
    if not BRep_Tool.IsClosed_s(shell):
        return None
    solid, builder = TopoDS_Solid(), BRep_Builder()
    builder.MakeSolid(solid)
    builder.Add(solid, shell)
    if not BRepLib.OrientClosedSolid_s(solid) or not is_valid(solid):
        return None
    return solid
