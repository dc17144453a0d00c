"""Options objects and keyword functions: one set of choices, given either way.

A public function such as :func:`robodyn.identify` or :func:`robodyn.simulate` takes its choices as
keywords and, equally, as one frozen options object (``options=``) that checks them when it is
made. :func:`resolve` builds the object from the keywords, or takes the one given and refuses
keywords given beside it.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import fields
from typing import Any, TypeVar

import numpy as np

__all__ = ["keywords_given", "resolve"]

T = TypeVar("T")


def keywords_given(cls: type, values: Mapping[str, Any]) -> list[str]:
    """The fields of the dataclass ``cls`` whose value in ``values`` is not the field's default
    (an array or a container counts as given)."""
    out = []
    for f in fields(cls):
        v, d = values[f.name], f.default
        same = v is d or (not isinstance(v, np.ndarray | list | tuple | Mapping) and type(v) is type(d)
                          and v == d)
        if not same:
            out.append(f.name)
    return out


def resolve(cls: type[T], options: T | None, keywords: dict[str, Any], error: type[Exception]) -> T:
    """``options`` (an instance of ``cls``), or ``cls(**keywords)``; ``error`` when ``options``
    is not a ``cls`` or comes with keywords other than their defaults."""
    if options is None:
        return cls(**keywords)
    if not isinstance(options, cls):
        raise error(f"options: expected {cls.__name__}, got {type(options).__name__}")
    given = keywords_given(cls, keywords)
    if given:
        raise error(f"options: given together with the keyword(s) {', '.join(given)}; give the "
                    "choices either way, not both")
    return options
