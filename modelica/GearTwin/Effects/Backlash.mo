within GearTwin.Effects;
block Backlash "Finite circumferential clearance: the back flanks touch when the approach falls below -gap"
  parameter Real gap(unit = "m", min = 1e-6, max = 2e-4) = 5e-5 "Backlash along the line of action";
  input Real mesh_deflection(unit = "m") "Approach of the drive flanks along the line of action";
  input Real mesh_stiffness(unit = "N/m") "Instantaneous drive-side mesh stiffness, used for the back flanks too";
  output Real back_force(unit = "N") "Force of the back flanks along the line of action (negative: pushes the flanks apart)";
equation
  back_force = mesh_stiffness * noEvent(min(0.0, mesh_deflection + gap));
end Backlash;
