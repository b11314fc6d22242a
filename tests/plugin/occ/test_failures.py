"""OpenCascade's exceptions told by what they are: the derived classes too (in OCP they are
not subclasses of Standard_Failure), turned into the package's own types."""

from __future__ import annotations

import pytest
from OCP.Standard import Standard_ConstructionError, Standard_Failure, Standard_OutOfRange

from surfprep.errors import OpenCascadeError
from surfprep.plugin.occ.failures import describe, is_occ_failure, occ_failures


def test_derived_classes_are_not_standard_failures_in_ocp():
    assert not issubclass(Standard_OutOfRange, Standard_Failure)      # why this module exists


@pytest.mark.parametrize("cls", [Standard_Failure, Standard_OutOfRange, Standard_ConstructionError])
def test_every_occ_exception_is_recognised(cls):
    assert is_occ_failure(cls("x"))
    assert not is_occ_failure(ValueError("x"))


def test_messages_name_the_class_when_occt_says_little():
    assert describe(Standard_OutOfRange("NCollection_IndexedMap::FindKey")) == \
        "Standard_OutOfRange: NCollection_IndexedMap::FindKey"
    assert describe(Standard_Failure("")) == "Standard_Failure"


def test_the_block_converts_occ_failures_and_nothing_else():
    with pytest.raises(OpenCascadeError, match="sewing failed: Standard_OutOfRange: out"):
        with occ_failures(OpenCascadeError, "sewing failed"):
            raise Standard_OutOfRange("out")
    with pytest.raises(KeyError):
        with occ_failures(OpenCascadeError, "sewing failed"):
            raise KeyError("not ours to convert")
