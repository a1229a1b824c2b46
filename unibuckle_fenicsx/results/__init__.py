"""What a solve returns, and its files.

- :mod:`.record`: :class:`~.record.BucklingResult` and the records it holds, with its
  JSON form and its terminal summary;
- :mod:`.assemble`: the result read off a live problem (collective);
- :mod:`.files`: the JSON file and the fields for ParaView.
"""

from unibuckle_fenicsx.results.record import BucklingResult

__all__ = ["BucklingResult"]
