within GearTwin;
model Gearbox21TiltingWalls "GearTwin.Gearbox21Shafts on casing walls that tilt the bearing housings: a bottom wall under both housings and a side wall beside each, whose bending and rotation move each housing in both directions"
  // GearTwin.Gearbox21Walls gives each housing one wall per direction, so a housing's horizontal
  // motion never reaches a vertical accelerometer on it. A bearing housing is a rigid boss standing
  // on the walls of a cast box: where a wall bends under it, the wall also rotates, and the shaft
  // centre, a lever arm away from the wall, moves across the wall's normal. Here
  //  * the bottom wall is one plate across the whole inside width of the casing (there is no wall
  //    under the middle of the box), clamped on its four edges (the corners with the side walls and
  //    the end walls), with both housings standing on it at +-centre_distance/2 from the middle.
  //    Its first two modes across the width, (1,1) and (2,1), move each housing vertically by the
  //    plate's deflection w under it and horizontally by -housing_height * dw/dx (the rotation of
  //    the plate where the housing stands, times the height of the shaft centre above the wall);
  //  * each side wall is a plate clamped at the bottom wall and at the end walls and simply
  //    supported at the bolted cover flange on top (a flange stops the edge moving but lets it
  //    rotate). Its first mode moves the housing beside it horizontally by the wall's deflection u
  //    and vertically by -side_lever * du/dy (the wall's rotation where the housing meets it, times
  //    the distance from the wall to the shaft centre).
  // The housings sit at mid-depth of every plate (the antinode along the shafts).
  //
  // Frequencies: Warburton (1954, Proc. IMechE 168, 371-384; Blevins, "Formulas for Natural
  // Frequency and Mode Shape", Table 11-4):
  //   f = (pi/2) sqrt(D/(rho h)) sqrt(Gx^4/a^4 + Gy^4/b^4 + 2 Hx Hy/(a^2 b^2)),  D = E h^3/(12 (1 - nu^2)),
  // clamped-clamped mode 1: G = 1.506, H = 1.248; mode 2: G = 2.5, H = 4.658; clamped-simply supported
  // mode 1: G = 1.25, H = 1.165. Shapes: Warburton's product of beam functions (Blevins, Table 8-1),
  // phi(s) = cosh(beta s) - cos(beta s) - sigma (sinh(beta s) - sin(beta s)), s from the clamped edge
  // as a fraction of the span, clamped-clamped beta = 4.730040745, sigma = 0.982502215 (mode 1) and
  // beta = 7.853204624, sigma = 1.000777312 (mode 2), clamped-pinned beta = 3.926602312,
  // sigma = 1.000777304;
  // each has mean square 1, so a plate of mass M whose mode is phi_x phi_y has modal mass M and, in
  // mass-normalised coordinates, moves a point by phi_x phi_y / sqrt(M) (1.5881 at mid-depth).
  // Both the drive of the modes by the pedestal forces and the motion of the housings use these
  // shapes (GearTwin.TiltingCasingWalls), so the coupling is symmetric.
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
  // 0.18 m deep along the shafts, 8 mm grey cast iron; the shaft centres 0.15 m above the bottom
  // wall: shaft_height 0.05 m above the casing's centre of mass, itself mount_height 0.10 m above
  // the feet under the bottom wall) --------------------------------------------------------------
  parameter Real casing_youngs_modulus(unit = "Pa", min = 0) = 1.1e11 "Young's modulus of the casing's grey cast iron (EN-GJL-250: 103-118 GPa)";
  parameter Real casing_poisson_ratio(min = 0, max = 0.5) = 0.26 "Poisson's ratio of the casing's cast iron";
  parameter Real casing_density(unit = "kg/m3", min = 0) = 7200 "Density of the casing's cast iron";
  parameter Real wall_thickness(unit = "m", min = 0) = 0.008 "Casing wall thickness of the panels that carry the bearing housings (cast)";
  parameter Real panel_depth(unit = "m", min = 0) = 0.18 "Wall panel size along the shafts (inside depth of the casing)";
  parameter Real side_panel_height(unit = "m", min = 0) = 0.25 "Side wall panel size, vertical, from the bottom wall to the cover flange";
  parameter Real bottom_wall_width(unit = "m", min = 0) = 0.30 "Bottom wall panel size across the casing between the side walls (both housings stand on it)";
  parameter Real housing_height(unit = "m", min = 0) = 0.15 "Tilt lever arm of the housings on the bottom wall: height of the shaft centres above it";
  parameter Real wall_damping(min = 0.005, max = 0.1) = 0.02 "Damping ratio of the wall modes (cast iron with bolted joints, 0.5-10 %)";
  parameter Real wall_rigidity(unit = "N.m") = casing_youngs_modulus * wall_thickness ^ 3 / (12 * (1 - casing_poisson_ratio ^ 2)) "Flexural rigidity D of the walls";
  parameter Real wall_wave_speed(unit = "m2/s") = 0.5 * GearTwin.pi * sqrt(wall_rigidity / (casing_density * wall_thickness)) "(pi/2) sqrt(D/(rho h)) of Warburton's formula";
  parameter Real side_wall_frequency(unit = "Hz") = wall_wave_speed * sqrt(1.25 ^ 4 / side_panel_height ^ 4 + 1.506 ^ 4 / panel_depth ^ 4 + 2 * 1.165 * 1.248 / (side_panel_height ^ 2 * panel_depth ^ 2)) "First natural frequency of a side wall (clamped at the bottom and end walls, simply supported at the cover flange; Warburton)";
  parameter Real bottom_wall_frequency(unit = "Hz") = wall_wave_speed * sqrt(1.506 ^ 4 / bottom_wall_width ^ 4 + 1.506 ^ 4 / panel_depth ^ 4 + 2 * 1.248 * 1.248 / (bottom_wall_width ^ 2 * panel_depth ^ 2)) "First natural frequency of the bottom wall, mode (1,1) (clamped on all edges; Warburton)";
  parameter Real bottom_wall_frequency2(unit = "Hz") = wall_wave_speed * sqrt(2.5 ^ 4 / bottom_wall_width ^ 4 + 1.506 ^ 4 / panel_depth ^ 4 + 2 * 4.658 * 1.248 / (bottom_wall_width ^ 2 * panel_depth ^ 2)) "Natural frequency of the bottom wall's mode (2,1), antisymmetric across the width (clamped on all edges; Warburton)";
  parameter Real side_wall_mass(unit = "kg") = casing_density * wall_thickness * side_panel_height * panel_depth "Mass of a side wall panel (its modal mass in the beam functions' normalisation)";
  parameter Real bottom_wall_mass(unit = "kg") = casing_density * wall_thickness * bottom_wall_width * panel_depth "Mass of the bottom wall panel (its modal mass in the beam functions' normalisation)";
  parameter Real depth_shape = 1.588146 "Clamped-clamped beam function (mode 1) at mid-depth, where the housings sit";
  // where the housings stand: the input housing at s_b from the bottom wall's left edge (the output
  // housing at 1 - s_b), both at s_s of the side wall's height from its clamped bottom edge, a
  // lever arm side_lever from the side wall
  parameter Real bottom_position = 0.5 * (1 - centre_distance / bottom_wall_width) "Input housing's position across the bottom wall from the input-side wall, fraction of its width";
  parameter Real side_position = housing_height / side_panel_height "Housings' height on the side walls from the bottom wall, fraction of the side walls' height";
  parameter Real side_lever(unit = "m") = 0.5 * (bottom_wall_width - centre_distance) "Distance from a side wall to the shaft centre beside it";
  // beam functions phi and their slopes dphi/ds at those positions
  parameter Real side_shape = cosh(3.926602312 * side_position) - cos(3.926602312 * side_position) - 1.000777304 * (sinh(3.926602312 * side_position) - sin(3.926602312 * side_position)) "Clamped-pinned beam function (mode 1) where the housings meet the side walls";
  parameter Real side_slope = 3.926602312 * (sinh(3.926602312 * side_position) + sin(3.926602312 * side_position) - 1.000777304 * (cosh(3.926602312 * side_position) - cos(3.926602312 * side_position))) "Its slope per fraction of the height";
  parameter Real bottom_shape_in[2] = {cosh(4.730040745 * bottom_position) - cos(4.730040745 * bottom_position) - 0.982502215 * (sinh(4.730040745 * bottom_position) - sin(4.730040745 * bottom_position)), cosh(7.853204624 * bottom_position) - cos(7.853204624 * bottom_position) - 1.000777312 * (sinh(7.853204624 * bottom_position) - sin(7.853204624 * bottom_position))} "Clamped-clamped beam functions (modes 1, 2) across the bottom wall under the input housing";
  parameter Real bottom_slope_in[2] = {4.730040745 * (sinh(4.730040745 * bottom_position) + sin(4.730040745 * bottom_position) - 0.982502215 * (cosh(4.730040745 * bottom_position) - cos(4.730040745 * bottom_position))), 7.853204624 * (sinh(7.853204624 * bottom_position) + sin(7.853204624 * bottom_position) - 1.000777312 * (cosh(7.853204624 * bottom_position) - cos(7.853204624 * bottom_position)))} "Their slopes per fraction of the width";
  parameter Real bottom_shape_out[2] = {bottom_shape_in[1], -bottom_shape_in[2]} "The same under the output housing (mirror position: mode 1 symmetric, mode 2 antisymmetric)";
  parameter Real bottom_slope_out[2] = {-bottom_slope_in[1], bottom_slope_in[2]} "Their slopes per fraction of the width under the output housing";
  GearTwin.TiltingCasingWalls casing(
    frequency = {side_wall_frequency, side_wall_frequency, bottom_wall_frequency, bottom_wall_frequency2},
    damping = fill(wall_damping, 4),
    reach_input_x = depth_shape * {side_shape / sqrt(side_wall_mass), 0, -housing_height * bottom_slope_in[1] / bottom_wall_width / sqrt(bottom_wall_mass), -housing_height * bottom_slope_in[2] / bottom_wall_width / sqrt(bottom_wall_mass)},
    reach_input_y = depth_shape * {-side_lever * side_slope / side_panel_height / sqrt(side_wall_mass), 0, bottom_shape_in[1] / sqrt(bottom_wall_mass), bottom_shape_in[2] / sqrt(bottom_wall_mass)},
    reach_output_x = depth_shape * {0, -side_shape / sqrt(side_wall_mass), -housing_height * bottom_slope_out[1] / bottom_wall_width / sqrt(bottom_wall_mass), -housing_height * bottom_slope_out[2] / bottom_wall_width / sqrt(bottom_wall_mass)},
    reach_output_y = depth_shape * {0, -side_lever * side_slope / side_panel_height / sqrt(side_wall_mass), bottom_shape_out[1] / sqrt(bottom_wall_mass), bottom_shape_out[2] / sqrt(bottom_wall_mass)},
    force = {pedestal_force_input_x, pedestal_force_input_y, pedestal_force_output_x, pedestal_force_output_y}) "Wall modes: input side wall, output side wall, bottom wall (1,1) and (2,1)";
end Gearbox21TiltingWalls;
