within GearTwin.Variants;
model Gearbox21WheelErrors "GearTwin.Gearbox21 with the gear's own tooth errors: one position deviation per gear tooth"
  // Every real gear has pitch deviations and run-out. The base model's per-tooth arrays are the
  // pinion's; this variant adds the gear's, tracked by the same count of completed mesh cycles
  // as the pinion's teeth, so at cycle k the current pair holds pinion tooth 1 + mod(k, z1) and
  // gear tooth 1 + mod(k, wheel_teeth). It costs about one and a half times the base model's
  // step (52 more teeth to select from), which is why it is a variant.
  extends GearTwin.Gearbox21(z2 = wheel_teeth, effect_pair_deviation = pair_wheel_offset);
  parameter Integer wheel_teeth = 52 "Number of gear teeth (structural: sizes wheel_tooth_deviation_offset; binds z2, which must not be set apart from it)";
  parameter Real wheel_tooth_deviation_offset[wheel_teeth](each unit = "m") = fill(0.0, wheel_teeth) "Per-gear-tooth extra material loss along the line of action (cumulative pitch deviation, run-out), added to the pinion tooth's in each pair";
  parameter Integer wheel_tooth_prev[wheel_teeth] = {if j == 1 then wheel_teeth else j - 1 for j in 1:wheel_teeth} "Index of the gear tooth ahead of gear tooth j (structural)";
  parameter Integer wheel_tooth_next[wheel_teeth] = {if j == wheel_teeth then 1 else j + 1 for j in 1:wheel_teeth} "Index of the gear tooth behind gear tooth j (structural)";
  Real wheel_tooth_angle(unit = "rad") "Angle 2*pi*k/wheel_teeth of the gear tooth that entered contact last (k = completed mesh cycles)";
  Real wheel_tooth_weight[wheel_teeth] "1 for the gear tooth of the current pair, 0 for the others";
  Real pair_wheel_offset[3](each unit = "m") "wheel_tooth_deviation_offset of the gear tooth in each pair (leading, current, next)";
equation
  wheel_tooth_angle = (mesh_angle - 2 * GearTwin.pi * cycle_fraction) / wheel_teeth;
  // The pinion's nearest-tooth selection, on the gear's tooth circle.
  wheel_tooth_weight = {noEvent(max(0.0, 1 - ((cos(wheel_tooth_angle) - cos(2 * GearTwin.pi * (j - 1) / wheel_teeth)) ^ 2 + (sin(wheel_tooth_angle) - sin(2 * GearTwin.pi * (j - 1) / wheel_teeth)) ^ 2) / sin(GearTwin.pi / wheel_teeth) ^ 2)) for j in 1:wheel_teeth};
  pair_wheel_offset = {sum(wheel_tooth_deviation_offset[wheel_tooth_prev[j]] * wheel_tooth_weight[j] for j in 1:wheel_teeth), sum(wheel_tooth_deviation_offset[j] * wheel_tooth_weight[j] for j in 1:wheel_teeth), sum(wheel_tooth_deviation_offset[wheel_tooth_next[j]] * wheel_tooth_weight[j] for j in 1:wheel_teeth)};
end Gearbox21WheelErrors;
