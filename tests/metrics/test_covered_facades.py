"""metrics.covered_facades: against a truth that counts only its covered facades (CityGML), a
method's own facades count where they lie on one; against any other truth nothing changes."""

from dataclasses import replace

import numpy as np
import pytest
from paths import FIXTURES

from dataset.core.classes import NO_FACADE, SemanticClass
from dataset.core.results import FacadeEstimate, MethodResult
from dataset.core.wwr import ClassAreas
from dataset.importers.citygml_import import import_citygml
from dataset.presets import build_building, preset_recipes
from metrics.covered_facades import (
    ON_FACADE_MAX_DISTANCE_M,
    counts_every_wall,
    facade_distance_limit_m,
    over_truth_facades,
)
from metrics.errors import building_errors, facade_errors

TOL = 1e-9


def _estimate(i, normal, centre, window, gross):
    return FacadeEstimate(id=i, wwr=window / gross if gross else None, window_area_m2=window,
                          facade_area_m2=gross, normal=tuple(normal), centre_m=tuple(centre))


def _result(scene, estimates):
    window = sum(e.window_area_m2 for e in estimates)
    gross = sum(e.facade_area_m2 for e in estimates)
    return MethodResult(scene=scene, method="perfect", protocol="train", wwr=window / gross,
                        window_area_m2=window, facade_area_m2=gross, facades=tuple(estimates),
                        facade_identity="own")


def _face_areas_normals(mesh):
    tri = mesh.vertices_m[mesh.faces]
    cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    area = 0.5 * np.linalg.norm(cross, axis=1)
    return tri, area, cross / np.maximum(2 * area, 1e-12)[:, None]


def _perfect_estimates(building):
    """What a method that reconstructs every wall exactly reports: the truth's covered facades
    (their areas, normals and outline centres), and one wall-only facade per plane of the
    walls the truth does not count (from the truth mesh: wall faces without a facade id,
    grouped by normal and plane offset, their area-weighted centre)."""
    truth = building.truth
    out = []
    for f in truth.facades:
        corners = np.concatenate([np.asarray(w) for w in truth.facade_outlines_m[f.id]])
        out.append(_estimate(len(out) + 1, f.normal, corners.mean(axis=0), f.window_area_m2,
                             f.facade_area_m2))
    mesh = building.mesh
    tri, area, normal = _face_areas_normals(mesh)
    wall = ((mesh.face_facade == NO_FACADE) & (mesh.face_label == int(SemanticClass.WALL))
            & (np.abs(normal[:, 2]) < 0.1) & (area > 0))
    centre = tri.mean(axis=1)
    keys = {}
    for k in np.flatnonzero(wall):
        n = np.round(normal[k] * 20) / 20
        keys.setdefault((*n, round(float(centre[k] @ normal[k]))), []).append(k)
    for faces in keys.values():
        w = area[faces]
        n = (normal[faces] * w[:, None]).sum(axis=0)
        out.append(_estimate(len(out) + 1, n / np.linalg.norm(n),
                             (centre[faces] * w[:, None]).sum(axis=0) / w.sum(), 0.0,
                             float(w.sum())))
    return tuple(out)


@pytest.mark.parametrize("building_id", ["4018259", "4018133", "4018149b"])
def test_a_perfect_method_gets_the_covered_truth_on_real_buildings(building_id):
    """Real LoD3 buildings: every wall measured exactly, the back and party walls included;
    over the covered facades the building figures equal the truth's (1e-9), and all walls
    together would not (the mismatch this rule removes)."""
    (building,) = import_citygml(FIXTURES / "citygml" / f"{building_id}.xml.xz")[:1]
    truth = building.truth
    assert not counts_every_wall(truth)
    assert facade_distance_limit_m(truth) == ON_FACADE_MAX_DISTANCE_M
    estimates = _perfect_estimates(building)
    result = _result(building_id, estimates)
    assert result.facade_area_m2 > 1.2 * truth.facade_area_m2  # the uncounted walls
    covered, note = over_truth_facades(result, truth)
    assert covered.window_area_m2 == pytest.approx(truth.window_area_m2, rel=TOL)
    assert covered.facade_area_m2 == pytest.approx(truth.facade_area_m2, rel=TOL)
    assert covered.wwr == pytest.approx(truth.wwr, rel=TOL)
    assert f"{len(truth.facades)} of {len(truth.facades)} reached" in note
    row = building_errors(result, truth)
    assert row.wwr_ape == pytest.approx(0.0, abs=1e-6) and "covered facades" in row.reason
    per_facade = [f for f in facade_errors(result, truth) if f.facade_id != 0]
    assert sorted(f.facade_id for f in per_facade) == [f.id for f in truth.facades]
    assert all(f.wwr_ape == pytest.approx(0.0, abs=1e-6) for f in per_facade
               if f.wwr_ape is not None)


def test_closed_form_a_parallel_wall_beyond_the_limit_is_left_out():
    """Covered facade 1 of a real building, measured twice: on it, and as a copy 3 m behind
    it (a rear wing facing the same way); only the first counts."""
    (building,) = import_citygml(FIXTURES / "citygml" / "4018133.xml.xz")[:1]
    truth = building.truth
    f = truth.facades[0]
    corners = np.concatenate([np.asarray(w) for w in truth.facade_outlines_m[f.id]])
    on = _estimate(1, f.normal, corners.mean(axis=0), 6.0, 20.0)
    near = _estimate(2, f.normal, corners.mean(axis=0) - 0.5 * np.asarray(f.normal), 1.0, 5.0)
    behind = _estimate(3, f.normal, corners.mean(axis=0) - 3.0 * np.asarray(f.normal), 0.0, 40.0)
    covered, note = over_truth_facades(_result("x", (on, near, behind)), truth)
    areas = ClassAreas(7.0, 18.0, 0.0)
    assert covered.window_area_m2 == pytest.approx(7.0, abs=TOL)
    assert covered.facade_area_m2 == pytest.approx(25.0, abs=TOL)
    assert covered.wwr == pytest.approx(areas.wwr, abs=TOL)
    assert note.endswith("1 estimated facades on walls the truth does not count")
    none_on, _ = over_truth_facades(_result("x", (behind,)), truth)
    assert none_on.wwr is None and "no estimated facade lies on a covered" in none_on.warnings[-1]
    assert building_errors(_result("x", (behind,)), truth).status == "failed"


def test_nothing_changes_against_a_truth_that_counts_every_wall():
    (recipe,) = [r for r in preset_recipes("tiny") if r.id == "tiny_l_shaped"]
    truth = build_building(recipe).truth
    assert counts_every_wall(truth) and facade_distance_limit_m(truth) is None
    far = _estimate(1, truth.facades[0].normal, (100.0, 100.0, 5.0), 3.0, 10.0)
    result = _result("x", (far,))
    assert over_truth_facades(result, truth) == (result, "")
    row = building_errors(result, truth)
    assert row.facade_est_m2 == 10.0 and "covered" not in row.reason
    truth_ids = replace(result, facade_identity="truth_id")
    assert over_truth_facades(truth_ids, truth) == (truth_ids, "")
