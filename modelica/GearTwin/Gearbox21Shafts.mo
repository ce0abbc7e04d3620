within GearTwin;
model Gearbox21Shafts "GearTwin.Gearbox21Casing with shafts that bend: each shaft-and-bearing spring from the shaft's geometry in series with the bearing, and the shaft's mass on the gear it carries"
  // Gearbox21 joins each gear body to the pedestals of its shaft by two springs (kx45, kx56 on the
  // input shaft; kx910, kx1011 on the output shaft, the same in y) with stated values. Here they come
  // from the geometry. A simply supported shaft of span L and bending stiffness E*I, loaded by the
  // gear at distance a from one bearing and b = L - a from the other, deflects under the gear by
  // F a^2 b^2 / (3 E I L): a bending stiffness k_bend = 3 E I L / (a^2 b^2) (48 E I / L^3 at
  // mid-span). The bearings take the shares b/L and a/L of the load, so the branch towards each
  // bearing is the part k_bend * share of the shaft in series with that bearing's radial stiffness
  // (separate horizontally and vertically). With rigid pedestals the gear then sees
  // 1 / (1/k_bend + (b/L)^2/k_bearing_a + (a/L)^2/k_bearing_b) exactly at mid-span and for equal
  // bearings; elsewhere the two-branch split is the lumped approximation.
  // The shaft's own mass (a steel cylinder over the span) moves with the gear: its Rayleigh share at
  // mid-span, 17/35, is added to the gear body's lateral mass; the rest moves with the bearings and
  // is left in the pedestal masses.
  extends GearTwin.Gearbox21Casing(
    m5 = pinion_mass + shaft_mass_share * shaft_mass_input,
    m10 = gear_mass + shaft_mass_share * shaft_mass_output,
    kx45 = 1 / (1 / ((1 - pinion_position) * bending_stiffness_input) + 1 / kx_bearing4),
    ky45 = 1 / (1 / ((1 - pinion_position) * bending_stiffness_input) + 1 / ky_bearing4),
    kx56 = 1 / (1 / (pinion_position * bending_stiffness_input) + 1 / kx_bearing6),
    ky56 = 1 / (1 / (pinion_position * bending_stiffness_input) + 1 / ky_bearing6),
    kx910 = 1 / (1 / ((1 - gear_position) * bending_stiffness_output) + 1 / kx_bearing9),
    ky910 = 1 / (1 / ((1 - gear_position) * bending_stiffness_output) + 1 / ky_bearing9),
    kx1011 = 1 / (1 / (gear_position * bending_stiffness_output) + 1 / kx_bearing11),
    ky1011 = 1 / (1 / (gear_position * bending_stiffness_output) + 1 / ky_bearing11));
  // ---- Shafts (stated geometry: 25 mm steel shafts, bearings about 0.15 m apart, each gear at
  // mid-span) -------------------------------------------------------------------------------------
  parameter Real shaft_youngs_modulus(unit = "Pa", min = 0) = 2.1e11 "Young's modulus of the shaft steel";
  parameter Real shaft_density(unit = "kg/m3", min = 0) = 7850 "Density of the shaft steel";
  parameter Real d_shaft_input(unit = "m", min = 0) = 0.025 "Input shaft diameter between its bearings (effective for bending)";
  parameter Real d_shaft_output(unit = "m", min = 0) = 0.025 "Output shaft diameter between its bearings (effective for bending)";
  parameter Real span_input(unit = "m", min = 0) = 0.15 "Input shaft bearing span, bearing 4 to bearing 6 (between the load centres of the bearings)";
  parameter Real span_output(unit = "m", min = 0) = 0.15 "Output shaft bearing span, bearing 9 to bearing 11 (between the load centres of the bearings)";
  parameter Real pinion_position(min = 0, max = 1) = 0.5 "Position of the pinion on the input shaft's span, from bearing 4 (0) to bearing 6 (1)";
  parameter Real gear_position(min = 0, max = 1) = 0.5 "Position of the gear on the output shaft's span, from bearing 9 (0) to bearing 11 (1)";
  parameter Real pinion_mass(unit = "kg", min = 0) = 0.6 "Pinion body (without the shaft)";
  parameter Real gear_mass(unit = "kg", min = 0) = 3.5 "Gear body (without the shaft)";
  parameter Real shaft_mass_share = 17 / 35 "Share of a shaft's mass that moves with a mid-span gear (Rayleigh, simply supported)";
  parameter Real bending_stiffness_input(unit = "N/m", min = 0) = 3 * shaft_youngs_modulus * (GearTwin.pi * d_shaft_input ^ 4 / 64) / (span_input ^ 3 * pinion_position ^ 2 * (1 - pinion_position) ^ 2) "Bending stiffness of the input shaft under the pinion (simply supported)";
  parameter Real bending_stiffness_output(unit = "N/m", min = 0) = 3 * shaft_youngs_modulus * (GearTwin.pi * d_shaft_output ^ 4 / 64) / (span_output ^ 3 * gear_position ^ 2 * (1 - gear_position) ^ 2) "Bending stiffness of the output shaft under the gear (simply supported)";
  parameter Real shaft_mass_input(unit = "kg", min = 0) = shaft_density * GearTwin.pi * d_shaft_input ^ 2 / 4 * span_input "Mass of the input shaft over its span";
  parameter Real shaft_mass_output(unit = "kg", min = 0) = shaft_density * GearTwin.pi * d_shaft_output ^ 2 / 4 * span_output "Mass of the output shaft over its span";
  // ---- Bearings (25 mm bore deep-groove ball bearings, about 1.5e8 N/m radially under a light
  // preload; the same in both directions until calibrated) --------------------------------------
  parameter Real kx_bearing4(unit = "N/m", min = 0) = 1.5e8 "Radial stiffness of bearing 4 (input shaft, motor side), horizontal";
  parameter Real ky_bearing4(unit = "N/m", min = 0) = 1.5e8 "Radial stiffness of bearing 4 (input shaft, motor side), vertical";
  parameter Real kx_bearing6(unit = "N/m", min = 0) = 1.5e8 "Radial stiffness of bearing 6 (input shaft, free end), horizontal";
  parameter Real ky_bearing6(unit = "N/m", min = 0) = 1.5e8 "Radial stiffness of bearing 6 (input shaft, free end), vertical";
  parameter Real kx_bearing9(unit = "N/m", min = 0) = 1.5e8 "Radial stiffness of bearing 9 (output shaft, free end), horizontal";
  parameter Real ky_bearing9(unit = "N/m", min = 0) = 1.5e8 "Radial stiffness of bearing 9 (output shaft, free end), vertical";
  parameter Real kx_bearing11(unit = "N/m", min = 0) = 1.5e8 "Radial stiffness of bearing 11 (output shaft, brake side), horizontal";
  parameter Real ky_bearing11(unit = "N/m", min = 0) = 1.5e8 "Radial stiffness of bearing 11 (output shaft, brake side), vertical";
end Gearbox21Shafts;
