"""twin.variables: what a user may give as a value for each FMI type, and what is read-only."""
from __future__ import annotations

import numpy as np
import pytest

from twin.errors import ParameterError
from twin.variables import Variable


def var(type_, **kw) -> Variable:
    base = dict(name="x", value_reference=1, type=type_, causality="parameter", variability="tunable",
                unit="", description="", start=None, initial="exact")
    return Variable(**{**base, **kw})


@pytest.mark.parametrize("type_,given,expected", [
    ("Real", "2e8", 2e8), ("Float64", 3, 3.0), ("Float32", "0.25", 0.25),
    ("Integer", "-4", -4), ("Integer", 7.0, 7), ("Int8", "-128", -128), ("UInt8", 255, 255),
    ("Int16", "  12 ", 12), ("UInt32", "4000000000", 4000000000),
    ("Int64", str(-2**63), -2**63), ("UInt64", str(2**64 - 1), 2**64 - 1),
    ("Boolean", "true", True), ("Boolean", "0", False), ("Boolean", True, True), ("Boolean", 1, True),
    ("String", "gear", "gear"), ("String", "", ""),
])
def test_values_are_converted_to_the_variable_type(type_, given, expected):
    got = var(type_).coerce(given)
    assert got == expected and type(got) is type(expected)


@pytest.mark.parametrize("type_,given,match", [
    ("Real", "stiff", "must be a number"), ("Real", "nan", "must be finite"), ("Real", True, "must be a number"),
    ("Float32", 1e39, "Float32 range"),
    ("Integer", 2.5, "whole number"), ("Integer", "2.5", "whole number"), ("Integer", 2**31, r"\[-2147483648"),
    ("Int8", 128, r"within \[-128, 127\]"), ("UInt8", -1, r"within \[0, 255\]"), ("UInt64", 2**64, "within"),
    ("Boolean", "maybe", "true or false"), ("Boolean", 2, "true or false"),
    ("String", 3.0, "must be a string"),
])
def test_values_that_do_not_fit_are_refused_by_name(type_, given, match):
    with pytest.raises(ParameterError, match=match) as info:
        var(type_).coerce(given)
    assert "'x'" in str(info.value)


def test_enumeration_by_item_name_or_value():
    mode = var("Enumeration", declared_type="Mode", items=(("off", 1), ("slow", 2), ("fast", 3)))
    assert mode.coerce("fast") == 3 and mode.coerce("2") == 2 and mode.coerce(1) == 1
    with pytest.raises(ParameterError, match=r"item of Mode: off \(1\), slow \(2\), fast \(3\); got 'medium'"):
        mode.coerce("medium")
    with pytest.raises(ParameterError, match="got 4"):
        mode.coerce(4)
    assert mode.format(3) == "fast (3)" and mode.item_name(2) == "slow"


def test_dtypes_follow_the_fmi_type():
    assert var("Real").dtype == np.float64 and var("Float32").dtype == np.float32
    assert var("UInt16").dtype == np.uint16 and var("Boolean").dtype == np.bool_
    assert var("Enumeration", fmi_version=2).dtype == np.int32      # an fmi2Integer
    assert var("Enumeration", fmi_version=3).dtype == np.int64      # an fmi3Int64
    assert var("String").dtype == object


def test_unsupported_types_and_arrays_are_named():
    assert "Binary variables are not supported" in var("Binary").unsupported_reason
    assert "array variable Float64[3]" in var("Float64", shape=(3,)).unsupported_reason
    with pytest.raises(ParameterError, match="'x' is a Clock variable"):
        var("Clock").coerce(1)


def test_read_only_variables_say_why():
    assert var("Real").read_only_reason("M") is None
    assert var("Real", causality="input", variability="continuous").read_only_reason("M") is None
    constant = var("Integer", causality="local", variability="constant", start=19)
    assert constant.read_only_reason("M") == (
        "'x' of M is a constant (value 19, fixed when the FMU was built); it is read-only: it cannot be set by "
        "--param, --input or a scenario; `twin info` lists it and --outputs (output.variables in a scenario) "
        "records it")
    assert "structural parameter" in var("UInt16", causality="structuralParameter",
                                         variability="fixed").read_only_reason("M")
    assert "calculated parameter" in var("Real", causality="calculatedParameter", variability="fixed",
                                         initial="calculated").read_only_reason("M")
    assert "has causality 'output'" in var("Real", causality="output", variability="continuous",
                                           initial="calculated").read_only_reason("M")
    # an output with an exact start value (a state) can be given its start value
    assert var("Real", causality="output", variability="continuous", initial="exact").read_only_reason("M") is None
