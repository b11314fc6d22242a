"""The Examples sections of the public verbs run and print what they show."""

from __future__ import annotations

import doctest

import pytest

import surfprep

VERBS = ["intersect", "reparametrize", "heal"]


@pytest.mark.parametrize("name", VERBS)
def test_examples_of_public_verbs(name):
    verb = getattr(surfprep, name)
    finder = doctest.DocTestFinder(recurse=False)
    (test,) = finder.find(verb, name, globs={})
    assert test.examples, f"surfprep.{name} has no Examples section"
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS)
    result = runner.run(test)
    assert result.failed == 0, f"{result.failed} example(s) of surfprep.{name} failed"
