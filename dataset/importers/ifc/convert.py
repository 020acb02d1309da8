"""An IFC model (ArchiCAD, Revit, ... export) -> :class:`envelope.truth.Building` with derived
truth.

Steps (docs/importing.md): IfcOpenShell triangulates every product in world coordinates,
openings subtracted, in metres (:func:`read_ifc`); each element's class comes from its
entity (:mod:`dataset.importers.ifc.classes`); the ground is the storey at grade
(:mod:`dataset.importers.ifc.ground`); then the mesh importer derives the truth
(:func:`dataset.importers.mesh.mesh_import.building_from_mesh`: open, touching, overlapping and
inside-out bodies are normal, nothing below the ground counts). Each IfcWindow's declared
OverallWidth x OverallHeight is listed beside its measured exterior area. The model's north
(:func:`north_of_ifc`) becomes the truth's ``north_deg``.
"""

from __future__ import annotations

import os
from collections import Counter
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from tqdm import tqdm

from dataset.importers.ifc.classes import SKIP, class_of_element, interior_flagged_entities
from dataset.importers.ifc.ground import GroundLevel, ground_level
from dataset.importers.import_config import ImportConfig
from dataset.importers.mesh.mesh_import import NoFacadeError, NoFootprintError, building_from_mesh
from envelope.classes import NO_FACADE, SemanticClass
from envelope.mesh import LabelledMesh
from envelope.orientation import NorthSource
from envelope.truth import Building

MAX_NAMED = 5
"""Errors and warnings name at most this many elements."""
MAX_SKIPPED_FRACTION = 0.5
"""An import in which IfcOpenShell cannot triangulate more than this share of the elements
is refused (a file of broken geometry); fewer are skipped with a warning."""


@dataclass(frozen=True)
class IfcElement:
    """One imported IFC product: its identity, our class and, for an IfcWindow or a part of
    one (a frame member, a glass plate), the window's GlobalId and name and its declared
    OverallWidth x OverallHeight in m² (None if not given)."""

    global_id: str
    ifc_type: str
    name: str
    label: SemanticClass
    declared_area_m2: float | None = None
    window_id: str | None = None
    window_name: str = ""


@dataclass(frozen=True)
class IfcModel:
    """The triangulated building of an IFC file, world frame, metres, z up.

    Attributes
    ----------
    mesh : LabelledMesh
        Every element's triangles (its own vertices), classes set, facade ids 0.
    face_element : (F,) int64
        Index into ``elements`` of each face.
    elements : tuple of IfcElement
    ground : GroundLevel or None
        The storey at grade (:func:`dataset.importers.ifc.ground.ground_level`), None
        without storeys.
    warnings : dict
        Kind of problem -> how many elements had it.
    skipped : tuple of IfcElement
        Elements IfcOpenShell could not triangulate.
    unit_scale : float
        Metres per file length unit.
    north : (float, NorthSource) or None
        :func:`north_of_ifc` of the file.
    """

    mesh: LabelledMesh
    face_element: np.ndarray
    elements: tuple[IfcElement, ...]
    ground: GroundLevel | None
    warnings: dict[str, int]
    skipped: tuple[IfcElement, ...]
    unit_scale: float
    north: tuple[float, NorthSource] | None = None


def read_ifc(path: str | Path, *, overrides: dict | None = None, progress: bool = True
             ) -> IfcModel:
    """Triangulate an IFC file's building elements with IfcOpenShell.

    Parameters
    ----------
    path
        ``.ifc`` file (IFC2X3, IFC4, IFC4X3), any length unit.
    overrides
        :func:`dataset.importers.ifc.classes.read_class_overrides` of the user's mapping.
    progress
        Show a progress bar over the elements.

    Raises
    ------
    ValueError
        Missing or unreadable file, or no element with geometry.
    """
    import ifcopenshell
    import ifcopenshell.geom
    import ifcopenshell.util.unit

    path = Path(path)
    if not path.is_file():
        raise ValueError(f"IFC file {path} does not exist")
    try:
        model = ifcopenshell.open(str(path))
    except Exception as exc:  # IfcOpenShell raises several types on bad files
        raise ValueError(f"cannot read {path} as IFC: {exc}") from exc
    unit_scale = float(ifcopenshell.util.unit.calculate_unit_scale(model))
    warnings: Counter[str] = Counter()
    wanted: dict[int, IfcElement] = {}
    interior = interior_flagged_entities(model)
    for product in sorted(model.by_type("IfcProduct"), key=lambda p: p.GlobalId):
        label = class_of_element(product, overrides, interior)
        if label == SKIP or product.Representation is None:
            continue
        if interior and label != class_of_element(product, overrides):
            warnings[f"{product.is_a()} with IsExternal = False: interior, classed other"] += 1
        if _has_parts(product):
            continue  # a whole whose parts carry the geometry (curtain wall, roof, window)
        window = product if product.is_a("IfcWindow") else _aggregate_window(product)
        wanted[product.id()] = IfcElement(
            product.GlobalId, product.is_a(), product.Name or "", SemanticClass(label),
            None if window is None else _declared_window_area_m2(window, unit_scale),
            None if window is None else window.GlobalId,
            "" if window is None else window.Name or "")
    if not wanted:
        raise ValueError(f"{path} has no building element with geometry (walls, slabs, ...)")

    settings = ifcopenshell.geom.settings()
    settings.set("use-world-coords", True)
    iterator = ifcopenshell.geom.iterator(
        settings, model, max(1, os.cpu_count() or 1), include=[model.by_id(i) for i in wanted]
    )
    shapes: dict[int, tuple[np.ndarray, np.ndarray]] = {}
    with tqdm(total=len(wanted), desc="IFC geometry", unit="element",
              disable=not progress) as bar:
        if iterator.initialize():
            while True:
                shape = iterator.get()
                g = shape.geometry
                shapes[shape.id] = (np.asarray(g.verts, dtype=np.float64).reshape(-1, 3),
                                    np.asarray(g.faces, dtype=np.int64).reshape(-1, 3))
                bar.update()
                if not iterator.next():
                    break
    vertices, faces, face_element, elements, skipped = [], [], [], [], []
    n_vertices = 0
    for product_id in sorted(wanted, key=lambda i: wanted[i].global_id):
        element = wanted[product_id]
        v, f = shapes.get(product_id, (np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)))
        if len(f) == 0:
            warnings[f"skipped {element.ifc_type}: IfcOpenShell could not triangulate it"] += 1
            skipped.append(element)
            continue
        vertices.append(v)
        faces.append(f + n_vertices)
        face_element.append(np.full(len(f), len(elements)))
        elements.append(element)
        n_vertices += len(v)
    if len(skipped) > MAX_SKIPPED_FRACTION * len(wanted):
        raise ValueError(
            f"{path}: IfcOpenShell could triangulate only {len(elements)} of the {len(wanted)} "
            f"elements with geometry; a truth without the other {len(skipped)} would be "
            f"wrong. They are {_name_skipped(skipped)}; IfcOpenShell says for the first: "
            f"{_triangulation_error(model, skipped[0], settings)}. Repair them in the "
            "authoring tool and export again, or map them to skip with --ifc-classes "
            '({"GlobalId": "skip"}) to import without them')
    f_all = np.concatenate(faces)
    labels = np.array([e.label for e in elements], dtype=np.uint8)[np.concatenate(face_element)]
    mesh = LabelledMesh(np.concatenate(vertices), f_all, labels, np.full(len(f_all), NO_FACADE))
    return IfcModel(mesh, np.concatenate(face_element), tuple(elements),
                    ground_level(model, unit_scale),
                    dict(sorted(warnings.items())), tuple(skipped), unit_scale,
                    north_of_ifc(model))


def north_of_ifc(model) -> tuple[float, NorthSource] | None:
    """The north an IFC model states, as ``(north_deg, source)``; ``None`` if it states none.

    ``north_deg`` is the clockwise angle from true north to the model's +y axis
    (:mod:`envelope.orientation`), which is IfcOpenShell's anticlockwise angle
    from project north to north. The geometric context's ``TrueNorth`` is used
    when given, else the ``IfcMapConversion``'s grid north (IFC2X3: ePSet_MapConversion).
    """
    import ifcopenshell.util.geolocation as geolocation

    contexts = model.by_type("IfcGeometricRepresentationContext", include_subtypes=False)
    if any(c.TrueNorth is not None for c in contexts):
        return float(geolocation.get_true_north(model)), "ifc_true_north"
    if geolocation.get_helmert_transformation_parameters(model) is not None:
        return float(geolocation.get_grid_north(model)), "ifc_map_conversion"
    return None


def import_ifc(
    path: str | Path,
    *,
    building_id: str | None = None,
    config: ImportConfig | None = None,
    overrides: dict | None = None,
    progress: bool = True,
) -> Building:
    """Read an IFC model and derive its ground truth (as :mod:`dataset.importer` does a mesh).

    The ground is ``config.ground_z_m`` when given, else the storey at grade
    (:mod:`dataset.importers.ifc.ground`; else the lowest point, with a warning). Open,
    overlapping, inside-out and single-face elements are taken as they are.
    ``truth.extra["ifc"]`` holds the element counts per class, the ground and why, the
    warnings and, per IfcWindow, its declared and measured exterior areas.

    Raises
    ------
    ValueError
        As :func:`read_ifc`; no facade or no footprint, naming the elements concerned.
    """
    path = Path(path)
    config = ImportConfig() if config is None else config
    if config.up_axis != "z":
        raise ValueError("IFC models are z-up; leave --up-axis at z")
    model = read_ifc(path, overrides=overrides, progress=progress)
    return building_from_ifc(model, path, building_id=building_id, config=config)


def building_from_ifc(model: IfcModel, path: str | Path, *, building_id: str | None = None,
                      config: ImportConfig | None = None) -> Building:
    """The building of a triangulated IFC model (:func:`read_ifc`), as :func:`import_ifc`
    derives it; ``path`` names the source in the truth and in errors."""
    path = Path(path)
    config = ImportConfig() if config is None else config
    warnings = dict(model.warnings)
    ground = _ground_record(model.ground, config)
    if config.ground_z_m is None:
        if model.ground is None:
            warnings["no storey: ground at the lowest point"] = 1
        else:
            config = replace(config, ground_z_m=model.ground.z_m)
            if model.ground.below:
                warnings["storeys below the ground, not facade: " + ", ".join(
                    f"{name} ({z:+.2f} m)" for name, z in model.ground.below)] = 1
    if not (model.mesh.face_label == SemanticClass.ROOF).any():
        warnings["no roof element: a virtual flat lid at the top closes the model for the "
                 "visibility test"] = 1
    try:
        building, parent = building_from_mesh(
            model.mesh, building_id=building_id if building_id is not None else path.stem,
            source=path, config=config, body_group=model.face_element,
        )
    except NoFacadeError as exc:
        raise ValueError(f"{exc}. The wall, window and door elements above the ground: "
                         f"{_name_elements(model, exc.facade_class_parents)}") from None
    except NoFootprintError as exc:
        raise ValueError(f"{exc}. Elements at that height: "
                         f"{_name_elements(model, exc.section_parents)}") from None
    if model.north is not None:
        north_deg, source = model.north
        building = replace(building, truth=replace(building.truth, north_deg=north_deg,
                                                   north_source=source))
    element_of_face = model.face_element[parent]
    building.truth.extra["ifc"] = {
        "elements": dict(sorted(Counter(e.label.name.lower() for e in model.elements).items())),
        "ground": ground,
        "warnings": warnings,
        "skipped": [{"global_id": e.global_id, "type": e.ifc_type, "name": e.name}
                    for e in model.skipped],
        "windows": _window_areas(model, building, element_of_face),
    }
    return building


def _window_areas(model: IfcModel, building: Building, element_of_face: np.ndarray
                  ) -> list[dict]:
    """Each IfcWindow's declared OverallWidth x OverallHeight beside its measured area (m²):
    the window-class faces of that window (or of its parts) that belong to a facade."""
    mesh = building.mesh
    counted = (mesh.face_facade != NO_FACADE) & (mesh.face_label == SemanticClass.WINDOW)
    measured = np.bincount(element_of_face[counted], weights=mesh.face_areas_m2()[counted],
                           minlength=len(model.elements))
    windows: dict[str, dict] = {}
    for i, e in enumerate(model.elements):
        if e.window_id is None:
            continue
        w = windows.setdefault(e.window_id, {
            "global_id": e.window_id, "name": e.window_name,
            "declared_area_m2": e.declared_area_m2, "measured_area_m2": 0.0})
        w["measured_area_m2"] += float(measured[i])
    return list(windows.values())


def _ground_record(ground: GroundLevel | None, config: ImportConfig) -> dict:
    """What ``truth.extra["ifc"]["ground"]`` says about the ground used."""
    if config.ground_z_m is not None:
        return {"z_m": config.ground_z_m, "storey": None, "reason": "given (--ground-z)"}
    if ground is None:
        return {"z_m": None, "storey": None, "reason": "no storey: the lowest point"}
    return {"z_m": ground.z_m, "storey": ground.storey, "reason": ground.reason,
            "below_grade_storeys": [{"name": n, "z_m": z} for n, z in ground.below]}


def _name_elements(model: IfcModel, faces: np.ndarray) -> str:
    """'IfcWall 2O2Fr... "Wall A"; ...' for the elements of ``faces`` (at most
    :data:`MAX_NAMED`, then how many more)."""
    index = np.unique(model.face_element[np.asarray(faces, dtype=np.int64)])
    named = [f"{model.elements[i].ifc_type} {model.elements[i].global_id} "
             f"{model.elements[i].name!r}" for i in index[:MAX_NAMED]]
    more = f" and {len(index) - MAX_NAMED} more" if len(index) > MAX_NAMED else ""
    return ("none" if not named else "; ".join(named)) + more


def _declared_window_area_m2(product, unit_scale: float) -> float | None:
    if not product.is_a("IfcWindow"):
        return None
    w, h = product.OverallWidth, product.OverallHeight
    return None if w is None or h is None else float(w * h) * unit_scale ** 2


def _name_skipped(skipped: list[IfcElement]) -> str:
    named = [f"{e.ifc_type} {e.global_id} {e.name!r}" for e in skipped[:MAX_NAMED]]
    more = f" and {len(skipped) - MAX_NAMED} more" if len(skipped) > MAX_NAMED else ""
    return "; ".join(named) + more


def _triangulation_error(model, element: IfcElement, settings) -> str:
    """IfcOpenShell's own message for an element it could not triangulate."""
    import ifcopenshell.geom

    try:
        ifcopenshell.geom.create_shape(settings, model.by_guid(element.global_id))
    except Exception as exc:  # IfcOpenShell raises RuntimeError and others
        return repr(exc)
    return "no error, but no faces"


def _aggregate_window(product):
    """The IfcWindow that ``product`` is a part of (directly), or None."""
    for rel in getattr(product, "Decomposes", None) or ():
        if rel.is_a("IfcRelAggregates") and rel.RelatingObject.is_a("IfcWindow"):
            return rel.RelatingObject
    return None


def _has_parts(product) -> bool:
    return any(rel.is_a("IfcRelAggregates") and rel.RelatedObjects
               for rel in getattr(product, "IsDecomposedBy", None) or ())


def warning_lines(ifc_record: dict, *, max_named: int = MAX_NAMED) -> list[str]:
    """One line per kind of warning with its count, then the first skipped elements by name.

    ``ifc_record`` is ``truth.extra["ifc"]`` of an imported building.
    """
    lines = [f"warning: {count} x {kind}" for kind, count in ifc_record["warnings"].items()]
    skipped = ifc_record["skipped"]
    lines += [f"warning: skipped {e['type']} {e['global_id']} {e['name']!r}"
              for e in skipped[:max_named]]
    if len(skipped) > max_named:
        lines.append(f"warning: ... and {len(skipped) - max_named} more skipped elements")
    return lines
