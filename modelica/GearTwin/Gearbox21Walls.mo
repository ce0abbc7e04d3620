within GearTwin;
model Gearbox21Walls "GearTwin.Gearbox21Shafts with flexible casing walls: each bearing housing sits on a wall panel whose bending mode the bearing forces drive and which moves the housing back; the accelerometers read the wall"
  // In Gearbox21Shafts the pedestals stand on a casing that is rigid in the gear plane, so a
  // shaft's lateral motion reaches the accelerometers only through the casing's rigid-body motion
  // on its mounts. Here each bearing housing is carried by a wall panel (stated geometry below)
  // that bends under the bearing load: the horizontal load by the side wall next to the housing,
  // the vertical load by the half of the bottom wall under it, each idealised as a rectangular
  // plate clamped on its four edges (the casing's corners, flanges and ribs), with the housing at
  // the centre of the plate (the antinode of its first mode). The wall modes are
  // GearTwin.CasingWalls, in mass-normalised coordinates casing.q[k], two-way: the pedestals'
  // forces drive them and their deflection moves the pedestals' supports. The accelerometers sit
  // on the housings, so they read the rigid casing plus the wall deflection under them.
  //
  // First natural frequency of a rectangular plate a x b, clamped on all edges (Warburton 1954,
  // "The vibration of rectangular plates", Proc. IMechE 168, 371-384; Blevins, "Formulas for
  // Natural Frequency and Mode Shape", Table 11-4), with beam-function constants G = 1.506,
  // H = J = 1.248 for a clamped-clamped first mode:
  //   f = (pi/2) sqrt(D / (rho h)) sqrt(G^4/a^4 + G^4/b^4 + 2 H^2 / (a^2 b^2)),
  //   D = E h^3 / (12 (1 - nu^2)).
  // For a square plate this gives lambda^2 = 36.1 against 35.99 exactly (Leissa, "Vibration of
  // Plates", NASA SP-160, 1969). The modal mass referred to the centre is the plate's mass times
  // the square of the clamped-clamped beam function's mean square over its centre value squared,
  // (1/1.5881^2)^2 = 0.3965^2 = 0.157 for the product shape.
  extends GearTwin.Gearbox21Shafts(
    support_input_x = x_casing - shaft_height * phi_casing + casing.displacement[1],
    support_input_y = y_casing - 0.5 * centre_distance * phi_casing + casing.displacement[2],
    support_output_x = x_casing - shaft_height * phi_casing + casing.displacement[3],
    support_output_y = y_casing + 0.5 * centre_distance * phi_casing + casing.displacement[4],
    support_input_vx = vx_casing - shaft_height * w_casing + casing.velocity[1],
    support_input_vy = vy_casing - 0.5 * centre_distance * w_casing + casing.velocity[2],
    support_output_vx = vx_casing - shaft_height * w_casing + casing.velocity[3],
    support_output_vy = vy_casing + 0.5 * centre_distance * w_casing + casing.velocity[4],
    sensor_pinion(near_acceleration = cos(sensor_angle_pinion) * (der(vy_casing) - 0.5 * centre_distance * der(w_casing) + casing.acceleration[2]) + sin(sensor_angle_pinion) * (der(vx_casing) - shaft_height * der(w_casing) + casing.acceleration[1]), far_acceleration = cos(sensor_angle_pinion) * (der(vy_casing) - 0.5 * centre_distance * der(w_casing) + casing.acceleration[2]) + sin(sensor_angle_pinion) * (der(vx_casing) - shaft_height * der(w_casing) + casing.acceleration[1])),
    sensor_gear(near_acceleration = cos(sensor_angle_gear) * (der(vy_casing) + 0.5 * centre_distance * der(w_casing) + casing.acceleration[4]) + sin(sensor_angle_gear) * (der(vx_casing) - shaft_height * der(w_casing) + casing.acceleration[3]), far_acceleration = cos(sensor_angle_gear) * (der(vy_casing) + 0.5 * centre_distance * der(w_casing) + casing.acceleration[4]) + sin(sensor_angle_gear) * (der(vx_casing) - shaft_height * der(w_casing) + casing.acceleration[3])));
  // ---- Walls (stated geometry: the cast box of Gearbox21Casing, 0.30 x 0.25 m in the gear plane,
  // 0.18 m deep along the shafts (the bearing span plus the housings), 8 mm grey cast iron) -------
  parameter Real casing_youngs_modulus(unit = "Pa", min = 0) = 1.1e11 "Young's modulus of the casing's grey cast iron (EN-GJL-250: 103-118 GPa)";
  parameter Real casing_poisson_ratio(min = 0, max = 0.5) = 0.26 "Poisson's ratio of the casing's cast iron";
  parameter Real casing_density(unit = "kg/m3", min = 0) = 7200 "Density of the casing's cast iron";
  parameter Real wall_thickness(unit = "m", min = 0) = 0.008 "Casing wall thickness of the panels that carry the bearing housings (cast)";
  parameter Real panel_depth(unit = "m", min = 0) = 0.18 "Wall panel size along the shafts (inside depth of the casing)";
  parameter Real side_panel_height(unit = "m", min = 0) = 0.25 "Side wall panel size, vertical (carries a housing's horizontal load)";
  parameter Real bottom_panel_width(unit = "m", min = 0) = 0.15 "Bottom wall panel size, horizontal, half the casing's width (carries a housing's vertical load)";
  parameter Real wall_damping(min = 0.005, max = 0.1) = 0.02 "Damping ratio of the wall modes (cast iron with bolted joints, 0.5-10 %)";
  parameter Real panel_modal_mass_share = 0.3965 ^ 2 "Modal mass of a clamped panel's first mode at its centre, as a share of the panel's mass";
  parameter Real wall_rigidity(unit = "N.m") = casing_youngs_modulus * wall_thickness ^ 3 / (12 * (1 - casing_poisson_ratio ^ 2)) "Flexural rigidity D of the walls";
  parameter Real side_wall_frequency(unit = "Hz") = 0.5 * GearTwin.pi * sqrt(wall_rigidity / (casing_density * wall_thickness)) * sqrt(1.506 ^ 4 / side_panel_height ^ 4 + 1.506 ^ 4 / panel_depth ^ 4 + 2 * 1.248 ^ 2 / (side_panel_height ^ 2 * panel_depth ^ 2)) "First natural frequency of a side wall panel (clamped plate, Warburton)";
  parameter Real bottom_wall_frequency(unit = "Hz") = 0.5 * GearTwin.pi * sqrt(wall_rigidity / (casing_density * wall_thickness)) * sqrt(1.506 ^ 4 / bottom_panel_width ^ 4 + 1.506 ^ 4 / panel_depth ^ 4 + 2 * 1.248 ^ 2 / (bottom_panel_width ^ 2 * panel_depth ^ 2)) "First natural frequency of a bottom wall panel (clamped plate, Warburton)";
  parameter Real side_wall_modal_mass(unit = "kg") = panel_modal_mass_share * casing_density * wall_thickness * side_panel_height * panel_depth "Modal mass of a side wall panel's first mode at the housing";
  parameter Real bottom_wall_modal_mass(unit = "kg") = panel_modal_mass_share * casing_density * wall_thickness * bottom_panel_width * panel_depth "Modal mass of a bottom wall panel's first mode at the housing";
  GearTwin.CasingWalls casing(frequency = {side_wall_frequency, bottom_wall_frequency, side_wall_frequency, bottom_wall_frequency}, damping = fill(wall_damping, 4), modal_mass = {side_wall_modal_mass, bottom_wall_modal_mass, side_wall_modal_mass, bottom_wall_modal_mass}, force = {pedestal_force_input_x, pedestal_force_input_y, pedestal_force_output_x, pedestal_force_output_y}) "Wall modes under the housings: input x, input y, output x, output y";
end Gearbox21Walls;
