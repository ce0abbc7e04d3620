within GearTwin.Variants;
model Gearbox21WheelErrors "GearTwin.Gearbox21 with the gear's own tooth errors: one position deviation per gear tooth"
  // Every real gear has pitch deviations and run-out. The base model's per-tooth arrays are the
  // pinion's; this variant adds the gear's, tracked by the same count of completed mesh cycles
  // as the pinion's teeth, so at cycle k the current pair holds pinion tooth 1 + mod(k, z1) and
  // gear tooth 1 + mod(k, wheel_teeth).
  extends GearTwin.Gearbox21(z2 = wheel_teeth, effect_pair_deviation = pair_wheel_offset);
  parameter Integer wheel_teeth = 52 "Number of gear teeth (structural: sizes wheel_tooth_deviation_offset; binds z2, which must not be set apart from it)";
  parameter Real wheel_tooth_deviation_offset[wheel_teeth](each unit = "m") = fill(0.0, wheel_teeth) "Per-gear-tooth extra material loss along the line of action (cumulative pitch deviation, run-out), added to the pinion tooth's in each pair";
  Real wheel_tooth_angle(unit = "rad") "Angle 2*pi*k/wheel_teeth of the gear tooth that entered contact last (k = completed mesh cycles)";
  Real wheel_pair_tooth[3] "Gear tooth (1..wheel_teeth, integer valued) in each pair: mod(k - 1, wheel_teeth) + 1, mod(k, wheel_teeth) + 1, mod(k + 1, wheel_teeth) + 1 with k = completed mesh cycles";
  Real pair_wheel_offset[3](each unit = "m") "wheel_tooth_deviation_offset of the gear tooth in each pair (leading, current, next)";
equation
  wheel_tooth_angle = (mesh_angle - 2 * GearTwin.pi * cycle_fraction) / wheel_teeth;
  // The pinion's tooth lookup, on the gear's teeth.
  wheel_pair_tooth = {noEvent(mod(integer(wheel_tooth_angle * wheel_teeth / (2 * GearTwin.pi) + 0.5) + i - 2, wheel_teeth)) + 1 for i in 1:3};
  pair_wheel_offset = {wheel_tooth_deviation_offset[noEvent(integer(wheel_pair_tooth[i]))] for i in 1:3};
end Gearbox21WheelErrors;
