within GearTwin;
model Gearbox21Rocking "GearTwin.Gearbox21Overhangs with the gear body rocking on its shaft: a tilt about each lateral axis, resisted by the shaft's bending and its bearings"
  // Gearbox21Overhangs carries each gear as a point mass on its shaft: it moves sideways but does
  // not tilt. A gear disk of diametral inertia I_d on a shaft also rocks about a diameter, resisted
  // by the slope stiffness of the shaft where it sits; the moment reaches the casing as a couple at
  // the two bearings. With the gear at s = a on a span L between simply supported bearings, a moment
  // M at the gear turns the shaft there by M (3 a^2 - 3 a L + L^2) / (3 E I L) (Roark; L / (12 E I)
  // at mid-span), and the couple M / L at the bearings (one pushed, one pulled) turns it by a further
  // M (1 / k_1 + 1 / k_2) / L^2. The tilt acts relative to the chord of the two pedestals:
  //   M = k_rock (phi - (u_2 - u_1) / L) + c_rock (d phi/dt - (v_2 - v_1) / L),
  //   I_d d^2 phi / dt^2 = -M,   pedestal 1 gets -M / L, pedestal 2 gets +M / L,
  // from the strain energy k_rock psi^2 / 2 of the relative tilt psi, so the model stays symmetric.
  // Only the gear rocks: the pinion (about 0.5 kg, tip radius 31 mm) would rock near 9 kHz on the
  // input shaft, above the band. Left out: the coupling of the tilt with the gear's translation
  // (none at mid-span, the stated position) and with the overhung ends, and the tilt's effect on the
  // mesh (a spur face of 20 mm: the misalignment it makes is small against the load).
  extends GearTwin.Gearbox21Overhangs(
    shaft_force_x9 = force_x9 - rocking_moment_x / span_output,
    shaft_force_x11 = force_x11 + rocking_moment_x / span_output,
    shaft_force_y9 = force_y9 - rocking_moment_y / span_output,
    shaft_force_y11 = force_y11 + rocking_moment_y / span_output);
  parameter Real I_rock10(unit = "kg.m2", min = 0) = 5.9e-3 "Diametral moment of inertia of the gear body (stated: a solid steel disk of the gear's mass, tip radius 81 mm, face 20 mm: m (3 r^2 + b^2) / 12)";
  parameter Real rocking_damping_ratio(min = 0) = 0.02 "Damping ratio of the gear's rocking on its shaft";
  parameter Real rocking_compliance_x(unit = "rad/(N.m)") = (3 * (gear_position * span_output) ^ 2 - 3 * gear_position * span_output ^ 2 + span_output ^ 2) / (3 * bending_rigidity_output * span_output) + (1 / kx_bearing9 + 1 / kx_bearing11) / span_output ^ 2 "Tilt of the gear per unit moment in the x-z plane: shaft bending and bearings";
  parameter Real rocking_compliance_y(unit = "rad/(N.m)") = (3 * (gear_position * span_output) ^ 2 - 3 * gear_position * span_output ^ 2 + span_output ^ 2) / (3 * bending_rigidity_output * span_output) + (1 / ky_bearing9 + 1 / ky_bearing11) / span_output ^ 2 "Tilt of the gear per unit moment in the y-z plane: shaft bending and bearings";
  parameter Real k_rock_x(unit = "N.m/rad") = 1 / rocking_compliance_x "Rocking stiffness of the gear on its shaft, x-z plane";
  parameter Real k_rock_y(unit = "N.m/rad") = 1 / rocking_compliance_y "Rocking stiffness of the gear on its shaft, y-z plane";
  parameter Real c_rock_x(unit = "N.m.s/rad") = 2 * rocking_damping_ratio * sqrt(k_rock_x * I_rock10) "Rocking damping, x-z plane";
  parameter Real c_rock_y(unit = "N.m.s/rad") = 2 * rocking_damping_ratio * sqrt(k_rock_y * I_rock10) "Rocking damping, y-z plane";
  Real phi_rock_x(unit = "rad", start = 0.0, fixed = true, nominal = 1e-5) "Tilt of the gear in the x-z plane (its slope dx/ds along the shaft)";
  Real w_rock_x(unit = "rad/s", start = 0.0, fixed = true, nominal = 1e-2) "Tilt rate of the gear in the x-z plane";
  Real phi_rock_y(unit = "rad", start = 0.0, fixed = true, nominal = 1e-5) "Tilt of the gear in the y-z plane (its slope dy/ds along the shaft)";
  Real w_rock_y(unit = "rad/s", start = 0.0, fixed = true, nominal = 1e-2) "Tilt rate of the gear in the y-z plane";
  Real rocking_moment_x(unit = "N.m") "Moment of the shaft on the gear against its tilt relative to the pedestals' chord, x-z plane (sign reversed)";
  Real rocking_moment_y(unit = "N.m") "Moment of the shaft on the gear against its tilt relative to the pedestals' chord, y-z plane (sign reversed)";
equation
  der(phi_rock_x) = w_rock_x;
  der(phi_rock_y) = w_rock_y;
  rocking_moment_x = k_rock_x * (phi_rock_x - (x11 - x9) / span_output) + c_rock_x * (w_rock_x - (vx11 - vx9) / span_output);
  rocking_moment_y = k_rock_y * (phi_rock_y - (y11 - y9) / span_output) + c_rock_y * (w_rock_y - (vy11 - vy9) / span_output);
  I_rock10 * der(w_rock_x) = -rocking_moment_x;
  I_rock10 * der(w_rock_y) = -rocking_moment_y;
end Gearbox21Rocking;
