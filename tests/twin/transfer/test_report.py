"""The assessment report: which files appear for labelled and unlabelled records, and bad paths."""
from __future__ import annotations

import numpy as np
import pytest

from twin.errors import OutputPathError
from twin.transfer.assessor import Assessment, RecordAssessment
from twin.transfer.errors import AssessorError
from twin.transfer.report import confusion_matrix, write_assessment_report


def _assessment(labelled: bool) -> Assessment:
    recs = (RecordAssessment("r0", 0, 0.9, (0.9, 0.1), (0, 0, 1), (0.9, 0.8, 0.6), 0 if labelled else None),
            RecordAssessment("r1", 1, 0.7, (0.3, 0.7), (1, 1, 1), (0.7, 0.7, 0.7), 1 if labelled else None))
    return Assessment(recs, 2, 1.0 if labelled else None, 5 / 6 if labelled else None)


def test_a_labelled_assessment_gets_its_confusion_matrix(tmp_path):
    page = write_assessment_report(_assessment(True), tmp_path / "rep", "title <&>")
    assert page == tmp_path / "rep" / "report.html"
    html = page.read_text()
    assert "title &lt;&amp;&gt;" in html and "windows 83.3 %" in html and "confusion.png" in html
    for name in ("stages.png", "confusion.png"):
        assert (tmp_path / "rep" / name).read_bytes()[:4] == b"\x89PNG"
    # the matrix drawn is the windows' (true, assessed): record r0 has one window assessed as stage 1
    np.testing.assert_array_equal(confusion_matrix(*_assessment(True).window_verdicts(), 2), [[2, 1], [0, 3]])


def test_an_unlabelled_assessment_gets_no_confusion_matrix(tmp_path):
    write_assessment_report(_assessment(False), tmp_path / "rep")
    assert sorted(p.name for p in (tmp_path / "rep").iterdir()) == ["report.html", "stages.png"]
    assert "confusion" not in (tmp_path / "rep" / "report.html").read_text()


def test_bad_report_paths_and_an_empty_assessment(tmp_path):
    with pytest.raises(OutputPathError, match="does not exist"):
        write_assessment_report(_assessment(True), tmp_path / "no" / "rep")
    (tmp_path / "f").write_text("keep")
    with pytest.raises(OutputPathError, match="is not a directory"):
        write_assessment_report(_assessment(True), tmp_path / "f")
    assert (tmp_path / "f").read_text() == "keep"
    with pytest.raises(AssessorError, match="no record"):
        write_assessment_report(Assessment((), 2, None, None), tmp_path / "empty")
