within GearTwin.Effects;
block ToothFriction "Coulomb sliding friction on the flanks; the sliding direction reverses at the pitch point"
  parameter Real friction_coefficient(min = 0, max = 0.15) = 0.06 "Coulomb friction coefficient of the lubricated contact";
  parameter Real reversal_width(min = 1e-3, max = 0.1) = 0.01 "Half-width of the smoothed sign change, as a fraction of the path of contact";
  parameter Real roll_pitch = 0.5 "Roll position of the pitch point";
  parameter Real contact_start_radius(unit = "m") = 0.005 "Distance from T1 to the start of contact";
  parameter Real contact_path_length(unit = "m") = 0.015 "Length of the path of contact";
  parameter Real line_of_action_length(unit = "m") = 0.03 "Distance T1-T2";
  input Real roll[3] "Roll positions of the three tracked pairs";
  input Real pair_force[3](each unit = "N") "Normal force of each pair";
  output Real pinion_torque(unit = "N.m") "Friction torque on the pinion";
  output Real gear_torque(unit = "N.m") "Friction torque on the gear, driven direction positive";
  output Real off_line_force(unit = "N") "Net friction force on the pinion across the line of action";
  Real friction_force[3](each unit = "N") "Signed friction force of each pair (positive in the recess, after the pitch point)";
equation
  friction_force = {friction_coefficient * pair_force[i] * tanh((roll[i] - roll_pitch) / reversal_width) for i in 1:3};
  pinion_torque = -sum(friction_force[i] * (contact_start_radius + roll[i] * contact_path_length) for i in 1:3);
  gear_torque = sum(friction_force[i] * (line_of_action_length - contact_start_radius - roll[i] * contact_path_length) for i in 1:3);
  off_line_force = -sum(friction_force);
end ToothFriction;
