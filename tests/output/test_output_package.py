"""``barhinge.output`` names its modules' public objects lazily: each name resolves to the
object of the module it comes from (the fields of a state from :mod:`barhinge.fields`)."""

from __future__ import annotations

import importlib

import pytest

import barhinge.output as output


@pytest.mark.parametrize("name", output.__all__)
def test_every_name_resolves_to_a_public_object_of_barhinge(name: str) -> None:
    obj = getattr(output, name)
    home = importlib.import_module(obj.__module__) if hasattr(obj, "__module__") else output
    assert home.__name__.startswith("barhinge.")
    assert getattr(home, name, obj) is obj


def test_the_fields_of_a_state_come_from_barhinge_fields() -> None:
    import barhinge.fields as fields

    assert output.state_data is fields.state_data
    assert output.state_mesh is fields.state_mesh


def test_an_unknown_name_is_an_attribute_error() -> None:
    with pytest.raises(AttributeError, match="no attribute 'write_everything'"):
        output.write_everything  # noqa: B018
