within GearTwin.Effects;
block DistributedWear "Uniform sliding wear of all pinion teeth: depth grows with the sliding distance, zero at the pitch point"
  parameter Integer n_profile = 11 "Nodes along the path of contact (structural)";
  parameter Real wear_depth(unit = "m", min = 0, max = 1e-4) = 5e-6 "Depth at the end of the path of contact farther from the pitch point";
  parameter Real roll_pitch = 0.5 "Roll position of the pitch point";
  parameter Real deviation[n_profile](each unit = "m") = {wear_depth * abs((n - 1) / (n_profile - 1) - roll_pitch) / max(roll_pitch, 1 - roll_pitch) for n in 1:n_profile} "Material missing at each node";
end DistributedWear;
