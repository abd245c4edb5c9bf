"""The metadata codec is an encode/decode pair: what the writer stores, the reader gets
back unchanged, through Parquet too."""

import math

import pyarrow as pa
import pyarrow.parquet as pq
from hypothesis import example, given, settings
from hypothesis import strategies as st

from vimpact.tableformat.metadata import (
    INT_KEYS,
    JSON_KEYS,
    META_PREFIX,
    decode_metadata,
    decode_value,
    encode_metadata,
    encode_value,
    read_metadata,
)

JSON_VALUES = st.recursive(
    st.none() | st.booleans() | st.integers(-2**62, 2**62)
    | st.floats(allow_nan=False) | st.text(max_size=20),
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=8), inner,
                                                                 max_size=4),
    max_leaves=12)
PLAIN_KEYS = st.text(st.characters(min_codepoint=97, max_codepoint=122), min_size=1,
                     max_size=12).filter(lambda k: k not in JSON_KEYS + INT_KEYS)


@st.composite
def metadata_values(draw) -> dict:
    """A metadata dict of the kinds the codec promises to keep: JSON keys with JSON
    values (not a str: a str for a JSON key is taken as JSON text already), integer
    keys with ints, any other key with a string."""
    values = {}
    for key in draw(st.lists(st.sampled_from(JSON_KEYS), unique=True)):
        values[key] = draw(JSON_VALUES.filter(lambda v: not isinstance(v, str)))
    for key in draw(st.lists(st.sampled_from(INT_KEYS), unique=True)):
        values[key] = draw(st.integers(-2**62, 2**62))
    for key in draw(st.lists(PLAIN_KEYS, unique=True, max_size=4)):
        values[key] = draw(st.text(max_size=30))
    return values


#: Every key the codec knows, each with a value at an edge of its kind: JSON floats at
#: the ends of the doubles (inf, the largest, the smallest subnormal, -0.0) and in
#: containers, non-ASCII text and dictionary keys, empty containers, the integer ends.
CORNERS = {
    **{key: value for key, value in zip(JSON_KEYS, [
        {"steps": 1000, "rtol": 1e-12, "continuum": True, "x": None},
        {"Q1": "1", "R_m": "m", "\u00b5": "\u00e9\u2603"},
        ["e_z", "beta_x", [], {}],
        {"ok": 2**62, "half_space": -(2**62)},
        [math.inf, -math.inf, 1.7976931348623157e308, 5e-324, -0.0],
        True, False, None, 0.1, -2.5e-300, {"a": {"b": {"c": [1, [2, [3.5]]]}}}, [None],
        {}, [], 2**53 + 1])},
    **{key: value for key, value in zip(INT_KEYS, [0, -(2**62), 2**62, 2**53 + 1, -1, 7,
                                                  10**18 + 1, 2**62 - 1])},
    "model": "", "mode": "\u00e9 \U0001f600 \n\t\"{}[]\"", "note": "12", "other": "true",
}


#: 50 random examples, and CORNERS: each of the codec's three rules (JSON, integer,
#: text) is a function of the key's kind alone, so every key of CORNERS meets its rule
#: at the edges of its values, and the random dicts (a few to all keys each, JSON
#: values of up to 12 leaves) vary the values around them. Hypothesis's generation of
#: the nested values is the whole cost (6 ms an example; 200 before).
@settings(max_examples=50, deadline=None, database=None)
@given(metadata_values())
@example(CORNERS)
def test_decode_inverts_encode(values):
    raw = encode_metadata(values)
    assert all(k.startswith(META_PREFIX.encode()) for k in raw)
    assert decode_metadata(raw) == values


@settings(max_examples=50, deadline=None, database=None)
@given(metadata_values())
def test_the_stored_text_decodes_and_encodes_back_to_itself(values):
    """On the text side the pair is an identity too: a stored entry re-encoded from its
    decoded value is the same text (a table rewritten keeps its metadata hash)."""
    for key, value in values.items():
        text = encode_value(key, value)
        assert encode_value(key, decode_value(key, text)) == text


def test_round_trip_through_a_parquet_file(tmp_path):
    values = {"model": "kelvin_voigt", "rows": 3, "seed": 7, "numerics": {"steps": 1000},
              "units": {"Q1": "1", "R_m": "m"}, "grid_tolerance": None, "rotation": True,
              "interpolation_error": {"outputs": {"e_z": {"max": 1.5e-6}}}}
    table = pa.table({"Q1": [0.1, 1.0, 10.0]})
    raw = {b"pandas": b"{}", **encode_metadata(values)}  # a foreign entry stays out
    pq.write_table(table.replace_schema_metadata(raw), tmp_path / "t.parquet")
    assert read_metadata(tmp_path / "t.parquet") == values


def test_undecodable_text_is_returned_as_it_is():
    assert decode_value("rows", "many") == "many"
    assert decode_value("numerics", "{not json") == "{not json"
    assert math.isinf(decode_value("grid_tolerance", "Infinity"))
