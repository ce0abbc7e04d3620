"""Measured (rig) and simulated (archive) vibration records: format, validating loader, writer.

Pure numpy/scipy/h5py, importable without fmpy. The format is specified in README.md in this
directory and implemented in :mod:`twin.measurements.format`.

::

    mset = load_measurements("rig.h5", min_duration=0.2, channels=["accel_pinion_casing"],
                             resample_to=100e3)           # MeasurementError lists every problem
    for label, records in mset.by_label().items(): ...
    print("\\n".join(mset.notes))                          # what was resampled, and how
    import_csv("run.csv", "run.h5")                        # CSV + run.csv.yaml -> HDF5
"""
from twin.measurements.format import (ACCEPTED_UNITS, ARCHIVE_FORMAT, FORMAT_VERSION, MEASUREMENT_FORMAT,
                                      RECORD_ATTRIBUTES, STANDARD_GRAVITY, UNITS)
from twin.measurements.load import iter_measurements, load_measurements, read_sidecar
from twin.measurements.record import MeasurementSet, Record
from twin.measurements.resample import resample_record
from twin.measurements.write import import_csv, write_measurements

__all__ = [
    "ACCEPTED_UNITS", "ARCHIVE_FORMAT", "FORMAT_VERSION", "MEASUREMENT_FORMAT", "MeasurementSet",
    "RECORD_ATTRIBUTES", "Record", "STANDARD_GRAVITY", "UNITS", "import_csv", "iter_measurements", "load_measurements",
    "read_sidecar", "resample_record", "write_measurements",
]
