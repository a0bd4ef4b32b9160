"""A reader of the particle files (`.vtu`, raw appended binary) written here in Python, apart
from the engine's, so the tests compare the package's arrays with the file itself."""

import re

import numpy as np

TYPES = {"Float64": "<f8", "Float32": "<f4", "UInt32": "<u4", "Int32": "<i4", "UInt8": "u1",
         "Int64": "<i8"}


def read(path):
    """{name: array} of every DataArray; vectors as (n, components)."""
    data = path.read_bytes()
    marker = data.index(b'<AppendedData encoding="raw">')
    start = data.index(b"_", marker) + 1
    header = data[:marker].decode()
    arrays = {}
    for tag in re.findall(r"<DataArray [^>]*>", header):
        attr = dict(re.findall(r'(\w+)="([^"]*)"', tag))
        offset = start + int(attr["offset"])
        nbytes = int(np.frombuffer(data, "<u8", 1, offset)[0])
        values = np.frombuffer(data, TYPES[attr["type"]], offset=offset + 8,
                               count=nbytes // np.dtype(TYPES[attr["type"]]).itemsize)
        comps = int(attr.get("NumberOfComponents", 1))
        arrays[attr["Name"]] = values.reshape(-1, comps) if comps > 1 else values
    return arrays
