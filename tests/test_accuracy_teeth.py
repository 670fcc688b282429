"""The image-wide accuracy measurement (lab/accuracy.py) sees a wrong pipeline."""

from lab.accuracy import gradient_accuracy


def test_gradient_accuracy_detects_a_wrong_pipeline(monkeypatch):
    from renderer import pointwise
    original = pointwise.exact_gradient
    monkeypatch.setattr(pointwise, "exact_gradient",
                        lambda *a: tuple(1.000001 * g for g in original(*a)))
    assert gradient_accuracy("sine", count=200)[0].max_ulps > 1e6
