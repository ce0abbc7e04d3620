within GearTwin.Effects;
block ShaftEccentricity "Run-out of a gear on its shaft: the mesh approach and the centre distance vary once per revolution, and the tilt that comes with it sweeps the lead"
  parameter Real eccentricity(unit = "m", min = 0, max = 2e-4) = 1e-5 "Distance between the pitch-circle centre and the axis of rotation";
  parameter Real phase(unit = "rad", min = -GearTwin.pi, max = GearTwin.pi) = 0 "Angle of the eccentricity vector at shaft angle 0, from the line of action";
  parameter Real wobble(unit = "m", min = 0, max = 2e-4) = 0 "Lead deviation across the face from the gear's tilt on its shaft (axial run-out over the face width), at its largest";
  parameter Real wobble_phase(unit = "rad", min = -GearTwin.pi, max = GearTwin.pi) = 0 "Angle of the tilt from that of the eccentricity";
  input Real shaft_angle(unit = "rad") "Angle of the shaft carrying the eccentric gear, counter-clockwise in the plane where the line of action points along (sin(alpha), cos(alpha)) (the pinion's theta5; the gear's -theta10)";
  input Real shaft_speed(unit = "rad/s") "Its time derivative";
  output Real mesh_displacement(unit = "m") "Eccentricity projected on the line of action";
  output Real mesh_displacement_rate(unit = "m/s") "Its time derivative";
  output Real off_line_displacement(unit = "m") "Eccentricity projected on the normal to the line of action in the plane of the gears, positive where the centre distance shrinks";
  output Real lead_mismatch(unit = "m") "The tilt's lead deviation in the plane of action";
equation
  mesh_displacement = eccentricity * sin(shaft_angle + phase);
  mesh_displacement_rate = eccentricity * shaft_speed * cos(shaft_angle + phase);
  off_line_displacement = eccentricity * cos(shaft_angle + phase);
  lead_mismatch = wobble * cos(shaft_angle + phase + wobble_phase);
end ShaftEccentricity;
