"""Diagnosis groundwork: measured data in, measured-like data out.

    data = read_measured("bench.csv", model_sensor_units(mechanism), mapping={"Weg": "sealing_rod_displacement"})
    report = synthesize(SynthesisRequest(config, overrides, sensors=["slider_displacement"], ...))
"""

from clearsim.diagnose.measured import MeasuredData, MeasuredDataError, model_sensor_units, read_measured

__all__ = ["MeasuredData", "MeasuredDataError", "model_sensor_units", "read_measured"]
