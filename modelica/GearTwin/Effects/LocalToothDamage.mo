within GearTwin.Effects;
block LocalToothDamage "One pinion tooth with reduced stiffness and missing material (root crack, spall)"
  parameter Integer z1 = 19 "Number of pinion teeth (structural)";
  parameter Integer tooth = 1 "Damaged tooth (structural; only the phase within a revolution depends on it)";
  parameter Real stiffness_loss(min = 0, max = 0.9) = 0.3 "Relative loss of pair stiffness while the tooth is in contact";
  parameter Real material_loss(unit = "m", min = 0, max = 2e-5) = 0 "Depth of material missing over the whole flank (spall)";
  parameter Real tooth_factor[z1] = {if j == tooth then 1 - stiffness_loss else 1.0 for j in 1:z1} "Per-tooth stiffness factor";
  parameter Real tooth_offset[z1](each unit = "m") = {if j == tooth then material_loss else 0.0 for j in 1:z1} "Per-tooth material loss";
end LocalToothDamage;
