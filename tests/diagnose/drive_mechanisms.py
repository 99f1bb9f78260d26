"""Small force-driven mechanisms for the drive candidates: a 10 kg block on a prismatic guide, held by a spring, pushed
by a hydraulic cylinder from an accumulator (the case of tests/validation/test_hydraulic_drive.py at default
tolerances), or released by a preloaded spring drive into a dashpot, against a gas load and guide friction."""

import yaml

from tests.validation.test_hydraulic_drive import CYLINDER as VALIDATION_CYLINDER


def _bench_cylinder() -> str:
    """The validation case with its accuracy settings left at the defaults, travel and speed sensors, 40 ms."""
    document = yaml.safe_load(VALIDATION_CYLINDER)
    document["forces"][1] = {k: v for k, v in document["forces"][1].items()
                             if k not in ("bulk_modulus", "density", "discharge_coefficient", "transition_pressure",
                                          "tank_pressure")}
    document["sensors"] = [{"name": "travel", "type": "point_displacement", "body": "block", "direction": [1, 0]},
                           {"name": "speed", "type": "point_velocity", "body": "block", "direction": [1, 0]}]
    document["output"] = {"displacement": "travel", "velocity": "speed"}
    document["solver"] = {"t_end": "40 ms", "output_rate": "10 kHz"}
    return yaml.safe_dump(document, sort_keys=False)


CYLINDER = _bench_cylinder()

SPRING_DRIVE = """
name: spring drive releasing a block into a dashpot
points: {O: [0 m, 0 m], C: [-0.5 m, 0 m]}
bodies:
  - {name: block, mass: 10 kg, inertia: 0.01 kg*m^2, position: [0 m, 0 m]}
joints:
  - {name: guide, type: prismatic, bodies: [ground, block], at: O, axis: [1, 0]}
forces:
  - {name: opening_spring, type: spring_drive, bodies: [ground, block], at: [C, O], stiffness: 2e4 N/m, preload: 3000 N}
  - {name: end_damper, type: dashpot, bodies: [ground, block], at: [C, O], sense: lengthening, damping: 800 N*s/m,
     engaged: [60 mm, 200 mm], engagement_length: 5 mm}
  - {name: puffer, type: gas_load, body: block, direction: [1, 0], area: 20 cm^2, volume: 1 L, gamma: 1.4,
     stroke: 150 mm}
  - name: fingers
    type: guide_friction
    joint: guide
    normal_force: 500 N
    friction: {law: coulomb, mu_d: 0.2, stick: smooth}
sensors:
  - {name: travel, type: point_displacement, body: block, direction: [1, 0]}
  - {name: speed, type: point_velocity, body: block, direction: [1, 0]}
output: {displacement: travel, velocity: speed}
solver: {t_end: 40 ms, output_rate: 10 kHz}
"""
