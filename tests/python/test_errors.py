"""The exceptions: what each is a kind of, and the CLI's exit code each carries as exit_code."""
import numpy as np
import pytest

import dpoint


def test_the_exception_classes():
    assert issubclass(dpoint.Error, ValueError)
    assert issubclass(dpoint.DeviceError, RuntimeError)
    assert not issubclass(dpoint.DeviceError, dpoint.Error)
    # raised by the package itself, without a code: bad input, and no device
    assert dpoint.Error("x").exit_code == 2
    assert dpoint.DeviceError("x").exit_code == 3


@pytest.mark.parametrize("call, kind, code", [
    (lambda: dpoint.generate("random2d", count=0), dpoint.Error, 1),                       # usage
    (lambda: dpoint.read("/nonexistent/x.ply"), dpoint.Error, 2),                          # bad input
    (lambda: dpoint.PointSet([[0.0, 0.0, np.nan]]), dpoint.Error, 2),                      # bad data
    (lambda: dpoint.render([[0.0, 0.0, 0.0]], device="99"), dpoint.DeviceError, 3),        # no device
    (lambda: dpoint.generate("random2d", count=10**7, max_memory="1M"), MemoryError, 4),   # resource limit
], ids=["usage", "bad-input", "bad-data", "no-device", "resource-limit"])
def test_each_failure_raises_its_kind_with_the_clis_code(call, kind, code):
    with pytest.raises(kind) as raised:
        call()
    assert raised.value.exit_code == code
    assert str(raised.value)  # a message, never empty
