within GearTwin.Effects;
block LoadTorqueFluctuation "Slow periodic fluctuation of the brake torque (brake control hunting, a pulsating load)"
  parameter Real amplitude(unit = "N.m", min = 0, max = 10) = 2 "Fluctuation amplitude";
  parameter Real frequency(unit = "Hz", min = 0.5, max = 15) = 4 "Fluctuation frequency";
  parameter Real phase(unit = "rad", min = -GearTwin.pi, max = GearTwin.pi) = 0 "Phase at t = 0";
  output Real torque(unit = "N.m") "Torque added to the brake torque";
equation
  torque = amplitude * sin(2 * GearTwin.pi * frequency * time + phase);
end LoadTorqueFluctuation;
