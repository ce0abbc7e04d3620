within GearTwin.Effects;
block MotorTorqueRipple "Air-gap torque ripple of the drive motor at an electrical frequency not locked to shaft speed"
  parameter Real amplitude(unit = "N.m", min = 0, max = 2) = 0.3 "Ripple torque amplitude";
  parameter Real frequency(unit = "Hz", min = 20, max = 400) = 100 "Ripple frequency (supply, inverter or slot harmonic)";
  parameter Real phase(unit = "rad", min = -GearTwin.pi, max = GearTwin.pi) = 0 "Phase at t = 0";
  output Real torque(unit = "N.m") "Torque added to the motor's slip torque";
equation
  torque = amplitude * sin(2 * GearTwin.pi * frequency * time + phase);
end MotorTorqueRipple;
