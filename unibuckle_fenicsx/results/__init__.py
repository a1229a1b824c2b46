"""What a solve returns, and its files.

- :mod:`.records`: :class:`~.records.BucklingResult` and the records it holds, with its
  JSON form and its terminal summary;
- :mod:`.assemble`: the result read off a live problem (collective);
- :mod:`.files`: the JSON file and the fields for ParaView;
- :mod:`.rounding`: a result as a record for version control (:func:`record`) and a
  figure's data to the digits every machine agrees on (:func:`rounded`).
"""

from unibuckle_fenicsx.results.records import BucklingResult
from unibuckle_fenicsx.results.rounding import RECORD_DIGITS, record, rounded

__all__ = ["RECORD_DIGITS", "BucklingResult", "record", "rounded"]
