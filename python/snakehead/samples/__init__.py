"""Sample robots and target sets for tests, benchmarks and the docs: snakes written the way published descriptions
are (:mod:`.published`, :mod:`.published_quirks`, :mod:`.published_xacro`; their URDF and robot-file text built by
:mod:`.urdf_text`) and head targets reachable by construction (:mod:`.targets`). Nothing else in the package imports
them."""
