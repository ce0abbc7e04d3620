within GearTwin.Effects;
block LocalToothDamage "One pinion tooth with a root crack (reduced stiffness) and a spall (material missing over part of its flank)"
  parameter Integer z1 = 19 "Number of pinion teeth (structural)";
  parameter Integer tooth = 1 "Damaged tooth (structural; only the phase within a revolution depends on it)";
  parameter Real stiffness_loss(min = 0, max = 0.9) = 0.3 "Relative loss of pair stiffness while the tooth is in contact";
  parameter Real spall_depth(unit = "m", min = 0, max = 2e-5) = 0 "Depth of material missing over the spall, across the whole face";
  parameter Real contact_ratio(min = 1) = 1.65 "Transverse contact ratio of the pair (bound to the gearbox's)";
  parameter Real roll_pitch(min = 0, max = 1) = 0.53 "Roll position of the pitch point (bound to the gearbox's)";
  parameter Real spall_start(min = 0, max = 1) = (contact_ratio - 1) / contact_ratio "Roll position where the spall begins (0 = pinion root end of the path of contact); default: the pinion's lowest point of single-tooth contact";
  parameter Real spall_end(min = 0, max = 1) = roll_pitch "Roll position where it ends; default: the pitch point";
  parameter Real edge_width(min = 1e-4, max = 0.1) = 0.005 "Roll length over which the contact crosses a spall edge: the Hertzian contact width over the path length (bound to the gearbox's)";
  parameter Real tooth_factor[z1] = {if j == tooth then 1 - stiffness_loss else 1.0 for j in 1:z1} "Per-tooth stiffness factor";
  input Real roll[3] "Roll position of each pair in contact (leading, current, next)";
  input Real pair_tooth[3] "Pinion tooth (1..z1, integer valued) in each pair";
  output Real pair_deviation[3](each unit = "m") "Material missing at each pair's contact: spall_depth while the damaged tooth's contact lies within the spall, 0 elsewhere";
equation
  // A spall has sharp edges: the contact falls into it over its own width, not over the spacing
  // of the profile nodes, so the step is written here along the roll, not on the nodes
  // (smoothstep over edge_width centred on each edge). max(0, 1 - |tooth_i - tooth|) is 1 for
  // the damaged tooth and 0 for every other (pair_tooth is integer valued).
  pair_deviation = {spall_depth * noEvent(max(0.0, 1 - abs(pair_tooth[i] - tooth))) * noEvent(min(1.0, max(0.0, (roll[i] - spall_start) / edge_width + 0.5))) ^ 2 * (3 - 2 * noEvent(min(1.0, max(0.0, (roll[i] - spall_start) / edge_width + 0.5)))) * noEvent(min(1.0, max(0.0, (spall_end - roll[i]) / edge_width + 0.5))) ^ 2 * (3 - 2 * noEvent(min(1.0, max(0.0, (spall_end - roll[i]) / edge_width + 0.5)))) for i in 1:3};
end LocalToothDamage;
