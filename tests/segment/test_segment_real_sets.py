"""The real-set readers (label mapping, refusals), the committed split lists, and the
figures of ``segment.real_measure`` / ``python -m segment.evaluate_real`` on folders in
the sets' layouts written by ``real_set_folders``."""

import csv
import io
from collections import defaultdict

import numpy as np
import pytest
from PIL import Image
from real_set_folders import (
    CMP_PHOTOS,
    LMF_PHOTOS,
    cmp_ids,
    expected_cmp_wwr,
    lmf_colours,
    write_cmp,
    write_labelmefacade,
)

from envelope.classes import SemanticClass as C
from segment.evaluate_real import evaluate_set, main
from segment.real_measure import facade_wwr, photo_result, split_scores, wwr_scores
from segment.real_sets import IGNORED, read_photo_pair, read_set
from segment.real_sets.cmp import CMP_CLASSES, cmp_labels
from segment.real_sets.common import PHOTO_SPLITS as SPLITS
from segment.real_sets.common import RealPhoto
from segment.real_sets.labelmefacade import labels_from_colours, photo_group
from segment.real_sets.splits import LIST_DIR, NONE, committed_splits, split_of, split_rule
from segment.segmenter import Segmenter


def test_labelmefacade_reader_maps_colours_and_reads_both_lists(tmp_path):
    root = write_labelmefacade(tmp_path / "lmf")
    photos = read_set("labelmefacade", root)
    assert [(p.name, p.part) for p in photos] == sorted(
        [(n, part) for n, part, _ in LMF_PHOTOS], key=lambda t: ("train", "test").index(t[1]))
    rgb, labels = read_photo_pair(photos[0])
    assert rgb.shape == (40, 30, 3) and labels.shape == (40, 30)
    assert labels[0, 0] == C.BACKGROUND and labels[15, 10] == C.WINDOW
    assert labels[30, 22] == C.DOOR and labels[25, 2] == C.WALL and labels[38, 5] == C.BACKGROUND
    assert labels[7, 1] == IGNORED
    assert photo_group("05june05_static_street_boston__p1010736") == (
        "05june05_static_street_boston")
    assert photo_group("spatial_envelope_256x256_static_8outdoorcategories__insidecity_art1184") \
        == "spatial_envelope_256x256_static_8outdoorcategories__insidecity_art"


def test_labelmefacade_reader_refuses_what_is_not_the_set(tmp_path):
    with pytest.raises(ValueError, match="not a LabelMeFacade folder"):
        read_set("labelmefacade", tmp_path)
    root = write_labelmefacade(tmp_path / "lmf")
    (root / "labels" / f"{LMF_PHOTOS[0][0]}.png").unlink()
    with pytest.raises(ValueError, match="is missing"):
        read_set("labelmefacade", root)
    odd = lmf_colours()
    odd[0, 0] = (1, 2, 3)
    with pytest.raises(ValueError, match="1:2:3 are none of LabelMeFacade's nine classes"):
        labels_from_colours(odd)


def test_cmp_reader_maps_every_id(tmp_path):
    root = write_cmp(tmp_path / "cmp")
    photos = read_set("cmp", root)
    assert [p.name for p in photos] == sorted(n for n, _ in CMP_PHOTOS)
    assert all(p.part == "base" and p.group == p.name for p in photos)
    _, labels = read_photo_pair(photos[0])
    ids = cmp_ids()
    for cmp_id, cls in CMP_CLASSES.items():
        np.testing.assert_array_equal(labels[ids == cmp_id], cls)
    # Every id, one pixel each, through a palette PNG.
    every = np.arange(13, dtype=np.uint8)[None]
    label = Image.frombytes("P", (13, 1), every.tobytes())
    label.putpalette([(k * 37) % 256 for k in range(3 * 13)])
    label.save(tmp_path / "all.png")
    assert cmp_labels(tmp_path / "all.png").tolist() == [[
        IGNORED, C.BACKGROUND, C.WALL, C.WINDOW, C.DOOR, C.WALL, C.WALL, C.OTHER, C.WALL,
        C.WALL, C.WALL, C.WALL, IGNORED]]


def test_cmp_reader_refuses_other_labels(tmp_path):
    Image.new("RGB", (4, 4)).save(tmp_path / "rgb.png")
    with pytest.raises(ValueError, match="one id per pixel"):
        cmp_labels(tmp_path / "rgb.png")
    label = Image.frombytes("P", (2, 1), bytes([2, 13]))
    label.putpalette([(k * 37) % 256 for k in range(3 * 14)])
    label.save(tmp_path / "13.png")
    with pytest.raises(ValueError, match=r"label ids \[13\]"):
        cmp_labels(tmp_path / "13.png")
    root = write_cmp(tmp_path / "cmp")
    (root / "base" / "label_names.txt").write_text("1 background 1\n2 window 2\n")
    with pytest.raises(ValueError, match="id 2 is 'window' here"):
        read_set("cmp", root)
    with pytest.raises(ValueError, match="holds no CMP facade"):
        read_set("cmp", tmp_path / "rgb.png")


def _listed(set_name):
    rows = list(csv.DictReader(io.StringIO((LIST_DIR / f"{set_name}.csv").read_text())))
    return [(RealPhoto(set_name, r["name"], r["group"], r["part"], LIST_DIR, LIST_DIR),
             r["split"]) for r in rows]


def test_committed_lists_are_the_rule_and_keep_groups_whole():
    lmf, cmp = _listed("labelmefacade"), _listed("cmp")
    assert len(lmf) == 945 and len(cmp) == 378  # every photo of the copies read
    for photo, split in lmf + cmp:
        assert split_rule(photo) == split, photo.name
    assert all(p.group == photo_group(p.name) for p, _ in lmf)
    assert all(p.group == p.name for p, _ in cmp)
    # LabelMeFacade: test photos only from its own test list; no group in two splits.
    assert all(p.part == "test" for p, s in lmf if s == "test")
    splits_of_group = defaultdict(set)
    for p, s in lmf:
        if s != NONE:
            splits_of_group[p.group].add(s)
    assert all(len(s) == 1 for s in splits_of_group.values())
    for photos in (lmf, cmp):
        assert {s for _, s in photos} >= set(SPLITS)
    committed = committed_splits("cmp")
    extended = RealPhoto("cmp", "cmp_x0001", "cmp_x0001", "extended", LIST_DIR, LIST_DIR)
    assert split_of(extended, committed) == "test"  # the extended set: test by the rule
    stranger = RealPhoto("cmp", "cmp_b9999", "cmp_b9999", "base", LIST_DIR, LIST_DIR)
    assert split_of(stranger, committed) == NONE


def _fixed_segmenter(labels: np.ndarray) -> Segmenter:
    return Segmenter("fixed", lambda rgb: labels.copy(), {"weights": "none"})


def test_measures_on_a_cmp_facade_are_the_closed_form(tmp_path):
    photo = read_set("cmp", write_cmp(tmp_path / "cmp"))[0]
    predicted = np.full((40, 30), C.WALL, np.uint8)
    predicted[10:20, 5:20] = C.WINDOW  # 150 px: the 100 window px and 50 wall px
    predicted[38:40, :] = C.WINDOW  # on the shop strip, which is not counted
    result = photo_result(photo, "test", _fixed_segmenter(predicted))
    scores = split_scores([result])
    assert scores.window_iou == pytest.approx(100 / 150)
    assert scores.window_precision == pytest.approx(100 / 150)
    assert scores.window_recall == pytest.approx(1.0)
    assert result.wwr_labels == pytest.approx(expected_cmp_wwr())
    counted = cmp_ids() != 12
    counted &= cmp_ids() != 0
    assert result.wwr_predicted == pytest.approx(facade_wwr(predicted[counted]))
    wwr = wwr_scores([result])
    error = (result.wwr_predicted - result.wwr_labels) * 100
    assert wwr.mean_abs_error_points == pytest.approx(abs(error))
    assert wwr.within_points == {5.0: float(abs(error) <= 5), 10.0: float(abs(error) <= 10)}
    guess = wwr_scores([result], constant=0.25)
    assert guess.mean_error_points == pytest.approx((0.25 - expected_cmp_wwr()) * 100)
    assert np.isnan(facade_wwr(np.zeros((3, 3), np.uint8)))


def test_evaluate_set_takes_the_committed_splits(tmp_path):
    photos = read_set("labelmefacade", write_labelmefacade(tmp_path / "lmf"))
    everything_wall = _fixed_segmenter(np.full((40, 30), C.WALL, np.uint8))
    results = evaluate_set(photos, everything_wall)
    expected = {s: [n for n, _, split in LMF_PHOTOS if split == s] for s in SPLITS}
    assert {s: [r.name for r in rows] for s, rows in results.items()} == expected
    assert split_scores(results["test"]).window_recall == 0.0
    # Choosing between segmenters reads the validation photos alone.
    only_val = evaluate_set(photos, everything_wall, splits=("val",))
    assert {s: [r.name for r in rows] for s, rows in only_val.items()} == {
        "test": [], "val": expected["val"], "train": []}


def test_evaluate_real_writes_the_report(tmp_path, capsys):
    lmf, cmp = write_labelmefacade(tmp_path / "lmf"), write_cmp(tmp_path / "cmp")
    out, per_photo = tmp_path / "report.md", tmp_path / "photos.csv"
    assert main(["--labelmefacade", str(lmf), "--cmp", str(cmp), "--out", str(out),
                 "--csv", str(per_photo), "--max-photos", "1", "--threads", "1"]) == 0
    text = out.read_text()
    rows = list(csv.DictReader(io.StringIO(per_photo.read_text())))
    assert len(rows) == 6 and {r["set"] for r in rows} == {"labelmefacade", "cmp"}
    cmp_wwr = {float(r["wwr_labels"]) for r in rows if r["set"] == "cmp"}
    assert cmp_wwr == {round(expected_cmp_wwr(), 4)}
    # The constant answer is the train facades' mean labels' WWR (all facades alike here).
    assert f"| test | constant {expected_cmp_wwr():.3f} | 1 |" in text
    assert "python -m segment.evaluate_real --labelmefacade" in text
    for row in ("| labelmefacade | test | 1 |", "| labelmefacade | val | 1 |",
                "| cmp | test | 1 |", "| cmp | train | 1 |"):
        assert row in text
    assert "## WWR on the rectified CMP facades" in text
    assert main(["--out", str(out)]) == 2
    assert "give --labelmefacade and/or --cmp" in capsys.readouterr().err
