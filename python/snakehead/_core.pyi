# The C++ core (pybind11 extension): its names are typed where the Python package wraps them.
from typing import Any

def __getattr__(name: str) -> Any: ...
