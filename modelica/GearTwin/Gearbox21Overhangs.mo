within GearTwin;
model Gearbox21Overhangs "GearTwin.Gearbox21Shafts with each shaft a beam through its gear and the parts it carries outside its bearings (couplings, slip rings, encoders)"
  // The paper's rig carries, outside the casing, a coupling half on the driven end of each shaft
  // (couplings 2 and 4) and a slip ring rotor, an adapter and a coupling to the encoder on each
  // free end (I7, I8). Its model keeps only their rotation. Here each shaft is a massless
  // Euler-Bernoulli beam on its two bearings that carries three masses sideways: the gear at s = g
  // on the span 0 <= s <= L (bearing at s = 0, the other at s = L), the end beside the first
  // bearing at s = -a and the end beside the second at s = L + b. On rigid bearings a unit force at
  // one point moves the others by the influence coefficients of a beam with overhangs (Roark):
  //   F_aa = a^2 (L + a) / (3 E I)        F_gg = g^2 (L - g)^2 / (3 E I L)    F_bb = b^2 (L + b) / (3 E I)
  //   F_ag = -a g (L - g) (2 L - g) / (6 E I L)    F_gb = -b g (L - g) (L + g) / (6 E I L)    F_ab = a b L / (6 E I)
  // (a load on the span lifts the overhangs; a load on one overhang pushes the other one with it).
  // The bearings are springs to the pedestals: a point at s moves with the shaft's centres at the
  // bearings by T1(s) = (L - s) / L and T2(s) = s / L, which also share the loads, so the bearings
  // add T1(s_i) T1(s_j) / k1 + T2(s_i) T2(s_j) / k2 to F. With K = F^-1 (the explicit inverse
  // below), the three masses feel -K r, r their displacements relative to the pedestals' chord
  // (r_i = u_i - T1(s_i) u_ped1 - T2(s_i) u_ped2), and the pedestals the reactions sum_i T(s_i) (K r)_i:
  // the statically condensed beam, symmetric by construction. Gearbox21Shafts' two springs per gear
  // are replaced by it (set to zero; their dampers stay); its gear masses and shaft geometry are kept.
  // The ends carry the part and their stub's Rayleigh tip share 33/140; the coupling ends are also
  // held by their elastomer couplings to the motor and the brake (about 1 kN/mm radially); the free
  // ends by nothing else (the slip ring's stator hangs on a torque arm). Left out: the gear's and the
  // parts' rotary inertia about a diameter (tilting), and shear.
  extends GearTwin.Gearbox21Shafts(
    kx45 = 0,
    kx56 = 0,
    kx910 = 0,
    kx1011 = 0,
    ky45 = 0,
    ky56 = 0,
    ky910 = 0,
    ky1011 = 0,
    shaft_force_x4 = force_x4,
    shaft_force_x6 = force_x6,
    shaft_force_x9 = force_x9,
    shaft_force_x11 = force_x11,
    shaft_force_x5 = force_x5,
    shaft_force_x10 = force_x10,
    shaft_force_y4 = force_y4,
    shaft_force_y6 = force_y6,
    shaft_force_y9 = force_y9,
    shaft_force_y11 = force_y11,
    shaft_force_y5 = force_y5,
    shaft_force_y10 = force_y10);
  // ---- The carried parts (stated: catalogue masses for 25 mm shafts) ----------------------------
  parameter Real end_mass4(unit = "kg", min = 0) = 0.35 "Coupling half on the input shaft's motor-side end (coupling 2), beside bearing 4";
  parameter Real end_mass6(unit = "kg", min = 0) = 0.6 "Slip ring rotor, adapter and coupling 3 on the input shaft's free end, beside bearing 6 (I7 as a 40 mm disk: 2 I7 / r^2)";
  parameter Real end_mass9(unit = "kg", min = 0) = 0.6 "Slip ring rotor, adapter and coupling 5 on the output shaft's free end, beside bearing 9 (I8 as a 40 mm disk)";
  parameter Real end_mass11(unit = "kg", min = 0) = 0.45 "Coupling half on the output shaft's brake-side end (coupling 4), beside bearing 11";
  parameter Real overhang4(unit = "m", min = 0) = 0.06 "Overhang of the input shaft beyond bearing 4 to the coupling half's centre";
  parameter Real overhang6(unit = "m", min = 0) = 0.09 "Overhang of the input shaft beyond bearing 6 to the centre of the slip ring and adapter";
  parameter Real overhang9(unit = "m", min = 0) = 0.09 "Overhang of the output shaft beyond bearing 9 to the centre of the slip ring and adapter";
  parameter Real overhang11(unit = "m", min = 0) = 0.06 "Overhang of the output shaft beyond bearing 11 to the coupling half's centre";
  parameter Real k_coupling_radial_input(unit = "N/m", min = 0) = 1.5e6 "Radial stiffness of the elastomer coupling that holds the input shaft's motor-side end";
  parameter Real k_coupling_radial_output(unit = "N/m", min = 0) = 1.5e6 "Radial stiffness of the elastomer coupling that holds the output shaft's brake-side end";
  parameter Real overhang_damping_ratio(min = 0) = 0.02 "Damping ratio of each end on the shaft (shaft hysteresis, bearing and fits)";
  parameter Real tip_mass_share = 33 / 140 "Share of a stub's mass that moves with its end (Rayleigh, uniform cantilever)";
  // ---- Derived --------------------------------------------------------------------------------
  parameter Real bending_rigidity_input(unit = "N.m2") = shaft_youngs_modulus * GearTwin.pi * d_shaft_input ^ 4 / 64 "E I of the input shaft";
  parameter Real bending_rigidity_output(unit = "N.m2") = shaft_youngs_modulus * GearTwin.pi * d_shaft_output ^ 4 / 64 "E I of the output shaft";
  parameter Real m_end4(unit = "kg") = end_mass4 + tip_mass_share * shaft_density * GearTwin.pi * d_shaft_input ^ 2 / 4 * overhang4 "Mass moving with the input shaft's motor-side end";
  parameter Real m_end6(unit = "kg") = end_mass6 + tip_mass_share * shaft_density * GearTwin.pi * d_shaft_input ^ 2 / 4 * overhang6 "Mass moving with the input shaft's free end";
  parameter Real m_end9(unit = "kg") = end_mass9 + tip_mass_share * shaft_density * GearTwin.pi * d_shaft_output ^ 2 / 4 * overhang9 "Mass moving with the output shaft's free end";
  parameter Real m_end11(unit = "kg") = end_mass11 + tip_mass_share * shaft_density * GearTwin.pi * d_shaft_output ^ 2 / 4 * overhang11 "Mass moving with the output shaft's brake-side end";
  parameter Real F_input_x_e1e1(unit = "m/N") = overhang4 ^ 2 * (span_input + overhang4) / (3 * bending_rigidity_input) + (span_input + overhang4) / span_input * (span_input + overhang4) / span_input / kx_bearing4 + (-overhang4 / span_input) * (-overhang4 / span_input) / kx_bearing6 "Influence coefficient of the input shaft, x: e1 under a unit force at e1 (beam and bearings)";
  parameter Real F_input_x_gg(unit = "m/N") = (pinion_position * span_input) ^ 2 * (span_input - pinion_position * span_input) ^ 2 / (3 * bending_rigidity_input * span_input) + (1 - pinion_position) * (1 - pinion_position) / kx_bearing4 + pinion_position * pinion_position / kx_bearing6 "Influence coefficient of the input shaft, x: g under a unit force at g (beam and bearings)";
  parameter Real F_input_x_e2e2(unit = "m/N") = overhang6 ^ 2 * (span_input + overhang6) / (3 * bending_rigidity_input) + (-overhang6 / span_input) * (-overhang6 / span_input) / kx_bearing4 + (span_input + overhang6) / span_input * (span_input + overhang6) / span_input / kx_bearing6 "Influence coefficient of the input shaft, x: e2 under a unit force at e2 (beam and bearings)";
  parameter Real F_input_x_e1g(unit = "m/N") = -overhang4 * pinion_position * span_input * (span_input - pinion_position * span_input) * (2 * span_input - pinion_position * span_input) / (6 * bending_rigidity_input * span_input) + (span_input + overhang4) / span_input * (1 - pinion_position) / kx_bearing4 + (-overhang4 / span_input) * pinion_position / kx_bearing6 "Influence coefficient of the input shaft, x: e1 under a unit force at g (beam and bearings)";
  parameter Real F_input_x_ge2(unit = "m/N") = -overhang6 * pinion_position * span_input * (span_input - pinion_position * span_input) * (span_input + pinion_position * span_input) / (6 * bending_rigidity_input * span_input) + (1 - pinion_position) * (-overhang6 / span_input) / kx_bearing4 + pinion_position * (span_input + overhang6) / span_input / kx_bearing6 "Influence coefficient of the input shaft, x: g under a unit force at e2 (beam and bearings)";
  parameter Real F_input_x_e1e2(unit = "m/N") = overhang4 * overhang6 * span_input / (6 * bending_rigidity_input) + (span_input + overhang4) / span_input * (-overhang6 / span_input) / kx_bearing4 + (-overhang4 / span_input) * (span_input + overhang6) / span_input / kx_bearing6 "Influence coefficient of the input shaft, x: e1 under a unit force at e2 (beam and bearings)";
  parameter Real det_input_x(unit = "m3/N3") = F_input_x_e1e1 * (F_input_x_gg * F_input_x_e2e2 - F_input_x_ge2 ^ 2) - F_input_x_e1g * (F_input_x_e1g * F_input_x_e2e2 - F_input_x_ge2 * F_input_x_e1e2) + F_input_x_e1e2 * (F_input_x_e1g * F_input_x_ge2 - F_input_x_gg * F_input_x_e1e2) "Determinant of the input shaft's influence matrix, x";
  parameter Real K_input_x_e1e1(unit = "N/m") = (F_input_x_gg * F_input_x_e2e2 - F_input_x_ge2 ^ 2) / det_input_x "Stiffness of the input shaft, x: force at e1 per displacement of e1 relative to the pedestals";
  parameter Real K_input_x_gg(unit = "N/m") = (F_input_x_e1e1 * F_input_x_e2e2 - F_input_x_e1e2 ^ 2) / det_input_x "Stiffness of the input shaft, x: force at g per displacement of g relative to the pedestals";
  parameter Real K_input_x_e2e2(unit = "N/m") = (F_input_x_e1e1 * F_input_x_gg - F_input_x_e1g ^ 2) / det_input_x "Stiffness of the input shaft, x: force at e2 per displacement of e2 relative to the pedestals";
  parameter Real K_input_x_e1g(unit = "N/m") = (F_input_x_e1e2 * F_input_x_ge2 - F_input_x_e1g * F_input_x_e2e2) / det_input_x "Stiffness of the input shaft, x: force at e1 per displacement of g relative to the pedestals";
  parameter Real K_input_x_e1e2(unit = "N/m") = (F_input_x_e1g * F_input_x_ge2 - F_input_x_e1e2 * F_input_x_gg) / det_input_x "Stiffness of the input shaft, x: force at e1 per displacement of e2 relative to the pedestals";
  parameter Real K_input_x_ge2(unit = "N/m") = (F_input_x_e1g * F_input_x_e1e2 - F_input_x_e1e1 * F_input_x_ge2) / det_input_x "Stiffness of the input shaft, x: force at g per displacement of e2 relative to the pedestals";
  parameter Real c_end4_x(unit = "N.s/m") = 2 * overhang_damping_ratio * sqrt(K_input_x_e1e1 * m_end4) "Damping of the end beside bearing 4 on its shaft, x";
  parameter Real c_end6_x(unit = "N.s/m") = 2 * overhang_damping_ratio * sqrt(K_input_x_e2e2 * m_end6) "Damping of the end beside bearing 6 on its shaft, x";
  parameter Real F_input_y_e1e1(unit = "m/N") = overhang4 ^ 2 * (span_input + overhang4) / (3 * bending_rigidity_input) + (span_input + overhang4) / span_input * (span_input + overhang4) / span_input / ky_bearing4 + (-overhang4 / span_input) * (-overhang4 / span_input) / ky_bearing6 "Influence coefficient of the input shaft, y: e1 under a unit force at e1 (beam and bearings)";
  parameter Real F_input_y_gg(unit = "m/N") = (pinion_position * span_input) ^ 2 * (span_input - pinion_position * span_input) ^ 2 / (3 * bending_rigidity_input * span_input) + (1 - pinion_position) * (1 - pinion_position) / ky_bearing4 + pinion_position * pinion_position / ky_bearing6 "Influence coefficient of the input shaft, y: g under a unit force at g (beam and bearings)";
  parameter Real F_input_y_e2e2(unit = "m/N") = overhang6 ^ 2 * (span_input + overhang6) / (3 * bending_rigidity_input) + (-overhang6 / span_input) * (-overhang6 / span_input) / ky_bearing4 + (span_input + overhang6) / span_input * (span_input + overhang6) / span_input / ky_bearing6 "Influence coefficient of the input shaft, y: e2 under a unit force at e2 (beam and bearings)";
  parameter Real F_input_y_e1g(unit = "m/N") = -overhang4 * pinion_position * span_input * (span_input - pinion_position * span_input) * (2 * span_input - pinion_position * span_input) / (6 * bending_rigidity_input * span_input) + (span_input + overhang4) / span_input * (1 - pinion_position) / ky_bearing4 + (-overhang4 / span_input) * pinion_position / ky_bearing6 "Influence coefficient of the input shaft, y: e1 under a unit force at g (beam and bearings)";
  parameter Real F_input_y_ge2(unit = "m/N") = -overhang6 * pinion_position * span_input * (span_input - pinion_position * span_input) * (span_input + pinion_position * span_input) / (6 * bending_rigidity_input * span_input) + (1 - pinion_position) * (-overhang6 / span_input) / ky_bearing4 + pinion_position * (span_input + overhang6) / span_input / ky_bearing6 "Influence coefficient of the input shaft, y: g under a unit force at e2 (beam and bearings)";
  parameter Real F_input_y_e1e2(unit = "m/N") = overhang4 * overhang6 * span_input / (6 * bending_rigidity_input) + (span_input + overhang4) / span_input * (-overhang6 / span_input) / ky_bearing4 + (-overhang4 / span_input) * (span_input + overhang6) / span_input / ky_bearing6 "Influence coefficient of the input shaft, y: e1 under a unit force at e2 (beam and bearings)";
  parameter Real det_input_y(unit = "m3/N3") = F_input_y_e1e1 * (F_input_y_gg * F_input_y_e2e2 - F_input_y_ge2 ^ 2) - F_input_y_e1g * (F_input_y_e1g * F_input_y_e2e2 - F_input_y_ge2 * F_input_y_e1e2) + F_input_y_e1e2 * (F_input_y_e1g * F_input_y_ge2 - F_input_y_gg * F_input_y_e1e2) "Determinant of the input shaft's influence matrix, y";
  parameter Real K_input_y_e1e1(unit = "N/m") = (F_input_y_gg * F_input_y_e2e2 - F_input_y_ge2 ^ 2) / det_input_y "Stiffness of the input shaft, y: force at e1 per displacement of e1 relative to the pedestals";
  parameter Real K_input_y_gg(unit = "N/m") = (F_input_y_e1e1 * F_input_y_e2e2 - F_input_y_e1e2 ^ 2) / det_input_y "Stiffness of the input shaft, y: force at g per displacement of g relative to the pedestals";
  parameter Real K_input_y_e2e2(unit = "N/m") = (F_input_y_e1e1 * F_input_y_gg - F_input_y_e1g ^ 2) / det_input_y "Stiffness of the input shaft, y: force at e2 per displacement of e2 relative to the pedestals";
  parameter Real K_input_y_e1g(unit = "N/m") = (F_input_y_e1e2 * F_input_y_ge2 - F_input_y_e1g * F_input_y_e2e2) / det_input_y "Stiffness of the input shaft, y: force at e1 per displacement of g relative to the pedestals";
  parameter Real K_input_y_e1e2(unit = "N/m") = (F_input_y_e1g * F_input_y_ge2 - F_input_y_e1e2 * F_input_y_gg) / det_input_y "Stiffness of the input shaft, y: force at e1 per displacement of e2 relative to the pedestals";
  parameter Real K_input_y_ge2(unit = "N/m") = (F_input_y_e1g * F_input_y_e1e2 - F_input_y_e1e1 * F_input_y_ge2) / det_input_y "Stiffness of the input shaft, y: force at g per displacement of e2 relative to the pedestals";
  parameter Real c_end4_y(unit = "N.s/m") = 2 * overhang_damping_ratio * sqrt(K_input_y_e1e1 * m_end4) "Damping of the end beside bearing 4 on its shaft, y";
  parameter Real c_end6_y(unit = "N.s/m") = 2 * overhang_damping_ratio * sqrt(K_input_y_e2e2 * m_end6) "Damping of the end beside bearing 6 on its shaft, y";
  parameter Real F_output_x_e1e1(unit = "m/N") = overhang9 ^ 2 * (span_output + overhang9) / (3 * bending_rigidity_output) + (span_output + overhang9) / span_output * (span_output + overhang9) / span_output / kx_bearing9 + (-overhang9 / span_output) * (-overhang9 / span_output) / kx_bearing11 "Influence coefficient of the output shaft, x: e1 under a unit force at e1 (beam and bearings)";
  parameter Real F_output_x_gg(unit = "m/N") = (gear_position * span_output) ^ 2 * (span_output - gear_position * span_output) ^ 2 / (3 * bending_rigidity_output * span_output) + (1 - gear_position) * (1 - gear_position) / kx_bearing9 + gear_position * gear_position / kx_bearing11 "Influence coefficient of the output shaft, x: g under a unit force at g (beam and bearings)";
  parameter Real F_output_x_e2e2(unit = "m/N") = overhang11 ^ 2 * (span_output + overhang11) / (3 * bending_rigidity_output) + (-overhang11 / span_output) * (-overhang11 / span_output) / kx_bearing9 + (span_output + overhang11) / span_output * (span_output + overhang11) / span_output / kx_bearing11 "Influence coefficient of the output shaft, x: e2 under a unit force at e2 (beam and bearings)";
  parameter Real F_output_x_e1g(unit = "m/N") = -overhang9 * gear_position * span_output * (span_output - gear_position * span_output) * (2 * span_output - gear_position * span_output) / (6 * bending_rigidity_output * span_output) + (span_output + overhang9) / span_output * (1 - gear_position) / kx_bearing9 + (-overhang9 / span_output) * gear_position / kx_bearing11 "Influence coefficient of the output shaft, x: e1 under a unit force at g (beam and bearings)";
  parameter Real F_output_x_ge2(unit = "m/N") = -overhang11 * gear_position * span_output * (span_output - gear_position * span_output) * (span_output + gear_position * span_output) / (6 * bending_rigidity_output * span_output) + (1 - gear_position) * (-overhang11 / span_output) / kx_bearing9 + gear_position * (span_output + overhang11) / span_output / kx_bearing11 "Influence coefficient of the output shaft, x: g under a unit force at e2 (beam and bearings)";
  parameter Real F_output_x_e1e2(unit = "m/N") = overhang9 * overhang11 * span_output / (6 * bending_rigidity_output) + (span_output + overhang9) / span_output * (-overhang11 / span_output) / kx_bearing9 + (-overhang9 / span_output) * (span_output + overhang11) / span_output / kx_bearing11 "Influence coefficient of the output shaft, x: e1 under a unit force at e2 (beam and bearings)";
  parameter Real det_output_x(unit = "m3/N3") = F_output_x_e1e1 * (F_output_x_gg * F_output_x_e2e2 - F_output_x_ge2 ^ 2) - F_output_x_e1g * (F_output_x_e1g * F_output_x_e2e2 - F_output_x_ge2 * F_output_x_e1e2) + F_output_x_e1e2 * (F_output_x_e1g * F_output_x_ge2 - F_output_x_gg * F_output_x_e1e2) "Determinant of the output shaft's influence matrix, x";
  parameter Real K_output_x_e1e1(unit = "N/m") = (F_output_x_gg * F_output_x_e2e2 - F_output_x_ge2 ^ 2) / det_output_x "Stiffness of the output shaft, x: force at e1 per displacement of e1 relative to the pedestals";
  parameter Real K_output_x_gg(unit = "N/m") = (F_output_x_e1e1 * F_output_x_e2e2 - F_output_x_e1e2 ^ 2) / det_output_x "Stiffness of the output shaft, x: force at g per displacement of g relative to the pedestals";
  parameter Real K_output_x_e2e2(unit = "N/m") = (F_output_x_e1e1 * F_output_x_gg - F_output_x_e1g ^ 2) / det_output_x "Stiffness of the output shaft, x: force at e2 per displacement of e2 relative to the pedestals";
  parameter Real K_output_x_e1g(unit = "N/m") = (F_output_x_e1e2 * F_output_x_ge2 - F_output_x_e1g * F_output_x_e2e2) / det_output_x "Stiffness of the output shaft, x: force at e1 per displacement of g relative to the pedestals";
  parameter Real K_output_x_e1e2(unit = "N/m") = (F_output_x_e1g * F_output_x_ge2 - F_output_x_e1e2 * F_output_x_gg) / det_output_x "Stiffness of the output shaft, x: force at e1 per displacement of e2 relative to the pedestals";
  parameter Real K_output_x_ge2(unit = "N/m") = (F_output_x_e1g * F_output_x_e1e2 - F_output_x_e1e1 * F_output_x_ge2) / det_output_x "Stiffness of the output shaft, x: force at g per displacement of e2 relative to the pedestals";
  parameter Real c_end9_x(unit = "N.s/m") = 2 * overhang_damping_ratio * sqrt(K_output_x_e1e1 * m_end9) "Damping of the end beside bearing 9 on its shaft, x";
  parameter Real c_end11_x(unit = "N.s/m") = 2 * overhang_damping_ratio * sqrt(K_output_x_e2e2 * m_end11) "Damping of the end beside bearing 11 on its shaft, x";
  parameter Real F_output_y_e1e1(unit = "m/N") = overhang9 ^ 2 * (span_output + overhang9) / (3 * bending_rigidity_output) + (span_output + overhang9) / span_output * (span_output + overhang9) / span_output / ky_bearing9 + (-overhang9 / span_output) * (-overhang9 / span_output) / ky_bearing11 "Influence coefficient of the output shaft, y: e1 under a unit force at e1 (beam and bearings)";
  parameter Real F_output_y_gg(unit = "m/N") = (gear_position * span_output) ^ 2 * (span_output - gear_position * span_output) ^ 2 / (3 * bending_rigidity_output * span_output) + (1 - gear_position) * (1 - gear_position) / ky_bearing9 + gear_position * gear_position / ky_bearing11 "Influence coefficient of the output shaft, y: g under a unit force at g (beam and bearings)";
  parameter Real F_output_y_e2e2(unit = "m/N") = overhang11 ^ 2 * (span_output + overhang11) / (3 * bending_rigidity_output) + (-overhang11 / span_output) * (-overhang11 / span_output) / ky_bearing9 + (span_output + overhang11) / span_output * (span_output + overhang11) / span_output / ky_bearing11 "Influence coefficient of the output shaft, y: e2 under a unit force at e2 (beam and bearings)";
  parameter Real F_output_y_e1g(unit = "m/N") = -overhang9 * gear_position * span_output * (span_output - gear_position * span_output) * (2 * span_output - gear_position * span_output) / (6 * bending_rigidity_output * span_output) + (span_output + overhang9) / span_output * (1 - gear_position) / ky_bearing9 + (-overhang9 / span_output) * gear_position / ky_bearing11 "Influence coefficient of the output shaft, y: e1 under a unit force at g (beam and bearings)";
  parameter Real F_output_y_ge2(unit = "m/N") = -overhang11 * gear_position * span_output * (span_output - gear_position * span_output) * (span_output + gear_position * span_output) / (6 * bending_rigidity_output * span_output) + (1 - gear_position) * (-overhang11 / span_output) / ky_bearing9 + gear_position * (span_output + overhang11) / span_output / ky_bearing11 "Influence coefficient of the output shaft, y: g under a unit force at e2 (beam and bearings)";
  parameter Real F_output_y_e1e2(unit = "m/N") = overhang9 * overhang11 * span_output / (6 * bending_rigidity_output) + (span_output + overhang9) / span_output * (-overhang11 / span_output) / ky_bearing9 + (-overhang9 / span_output) * (span_output + overhang11) / span_output / ky_bearing11 "Influence coefficient of the output shaft, y: e1 under a unit force at e2 (beam and bearings)";
  parameter Real det_output_y(unit = "m3/N3") = F_output_y_e1e1 * (F_output_y_gg * F_output_y_e2e2 - F_output_y_ge2 ^ 2) - F_output_y_e1g * (F_output_y_e1g * F_output_y_e2e2 - F_output_y_ge2 * F_output_y_e1e2) + F_output_y_e1e2 * (F_output_y_e1g * F_output_y_ge2 - F_output_y_gg * F_output_y_e1e2) "Determinant of the output shaft's influence matrix, y";
  parameter Real K_output_y_e1e1(unit = "N/m") = (F_output_y_gg * F_output_y_e2e2 - F_output_y_ge2 ^ 2) / det_output_y "Stiffness of the output shaft, y: force at e1 per displacement of e1 relative to the pedestals";
  parameter Real K_output_y_gg(unit = "N/m") = (F_output_y_e1e1 * F_output_y_e2e2 - F_output_y_e1e2 ^ 2) / det_output_y "Stiffness of the output shaft, y: force at g per displacement of g relative to the pedestals";
  parameter Real K_output_y_e2e2(unit = "N/m") = (F_output_y_e1e1 * F_output_y_gg - F_output_y_e1g ^ 2) / det_output_y "Stiffness of the output shaft, y: force at e2 per displacement of e2 relative to the pedestals";
  parameter Real K_output_y_e1g(unit = "N/m") = (F_output_y_e1e2 * F_output_y_ge2 - F_output_y_e1g * F_output_y_e2e2) / det_output_y "Stiffness of the output shaft, y: force at e1 per displacement of g relative to the pedestals";
  parameter Real K_output_y_e1e2(unit = "N/m") = (F_output_y_e1g * F_output_y_ge2 - F_output_y_e1e2 * F_output_y_gg) / det_output_y "Stiffness of the output shaft, y: force at e1 per displacement of e2 relative to the pedestals";
  parameter Real K_output_y_ge2(unit = "N/m") = (F_output_y_e1g * F_output_y_e1e2 - F_output_y_e1e1 * F_output_y_ge2) / det_output_y "Stiffness of the output shaft, y: force at g per displacement of e2 relative to the pedestals";
  parameter Real c_end9_y(unit = "N.s/m") = 2 * overhang_damping_ratio * sqrt(K_output_y_e1e1 * m_end9) "Damping of the end beside bearing 9 on its shaft, y";
  parameter Real c_end11_y(unit = "N.s/m") = 2 * overhang_damping_ratio * sqrt(K_output_y_e2e2 * m_end11) "Damping of the end beside bearing 11 on its shaft, y";
  // ---- States of the four ends, and the beams' forces -----------------------------------------
  Real x_end4(unit = "m", start = 0.0, fixed = true, nominal = 1e-6) "Horizontal displacement of the input shaft's motor-side end";
  Real vx_end4(unit = "m/s", start = 0.0, fixed = true, nominal = 1e-3) "Horizontal velocity of the input shaft's motor-side end";
  Real y_end4(unit = "m", start = 0.0, fixed = true, nominal = 1e-6) "Vertical displacement of the input shaft's motor-side end";
  Real vy_end4(unit = "m/s", start = 0.0, fixed = true, nominal = 1e-3) "Vertical velocity of the input shaft's motor-side end";
  Real x_end6(unit = "m", start = 0.0, fixed = true, nominal = 1e-6) "Horizontal displacement of the input shaft's free end";
  Real vx_end6(unit = "m/s", start = 0.0, fixed = true, nominal = 1e-3) "Horizontal velocity of the input shaft's free end";
  Real y_end6(unit = "m", start = 0.0, fixed = true, nominal = 1e-6) "Vertical displacement of the input shaft's free end";
  Real vy_end6(unit = "m/s", start = 0.0, fixed = true, nominal = 1e-3) "Vertical velocity of the input shaft's free end";
  Real x_end9(unit = "m", start = 0.0, fixed = true, nominal = 1e-6) "Horizontal displacement of the output shaft's free end";
  Real vx_end9(unit = "m/s", start = 0.0, fixed = true, nominal = 1e-3) "Horizontal velocity of the output shaft's free end";
  Real y_end9(unit = "m", start = 0.0, fixed = true, nominal = 1e-6) "Vertical displacement of the output shaft's free end";
  Real vy_end9(unit = "m/s", start = 0.0, fixed = true, nominal = 1e-3) "Vertical velocity of the output shaft's free end";
  Real x_end11(unit = "m", start = 0.0, fixed = true, nominal = 1e-6) "Horizontal displacement of the output shaft's brake-side end";
  Real vx_end11(unit = "m/s", start = 0.0, fixed = true, nominal = 1e-3) "Horizontal velocity of the output shaft's brake-side end";
  Real y_end11(unit = "m", start = 0.0, fixed = true, nominal = 1e-6) "Vertical displacement of the output shaft's brake-side end";
  Real vy_end11(unit = "m/s", start = 0.0, fixed = true, nominal = 1e-3) "Vertical velocity of the output shaft's brake-side end";
  Real r_input_x_e1(unit = "m") "Displacement of the input shaft's e1 relative to its pedestals' chord, x";
  Real r_input_x_g(unit = "m") "Displacement of the input shaft's g relative to its pedestals' chord, x";
  Real r_input_x_e2(unit = "m") "Displacement of the input shaft's e2 relative to its pedestals' chord, x";
  Real q_input_x_e1(unit = "N") "Force of the input shaft's beam on its e1 (restoring, sign reversed), x";
  Real q_input_x_g(unit = "N") "Force of the input shaft's beam on its g (restoring, sign reversed), x";
  Real q_input_x_e2(unit = "N") "Force of the input shaft's beam on its e2 (restoring, sign reversed), x";
  Real r_input_y_e1(unit = "m") "Displacement of the input shaft's e1 relative to its pedestals' chord, y";
  Real r_input_y_g(unit = "m") "Displacement of the input shaft's g relative to its pedestals' chord, y";
  Real r_input_y_e2(unit = "m") "Displacement of the input shaft's e2 relative to its pedestals' chord, y";
  Real q_input_y_e1(unit = "N") "Force of the input shaft's beam on its e1 (restoring, sign reversed), y";
  Real q_input_y_g(unit = "N") "Force of the input shaft's beam on its g (restoring, sign reversed), y";
  Real q_input_y_e2(unit = "N") "Force of the input shaft's beam on its e2 (restoring, sign reversed), y";
  Real r_output_x_e1(unit = "m") "Displacement of the output shaft's e1 relative to its pedestals' chord, x";
  Real r_output_x_g(unit = "m") "Displacement of the output shaft's g relative to its pedestals' chord, x";
  Real r_output_x_e2(unit = "m") "Displacement of the output shaft's e2 relative to its pedestals' chord, x";
  Real q_output_x_e1(unit = "N") "Force of the output shaft's beam on its e1 (restoring, sign reversed), x";
  Real q_output_x_g(unit = "N") "Force of the output shaft's beam on its g (restoring, sign reversed), x";
  Real q_output_x_e2(unit = "N") "Force of the output shaft's beam on its e2 (restoring, sign reversed), x";
  Real r_output_y_e1(unit = "m") "Displacement of the output shaft's e1 relative to its pedestals' chord, y";
  Real r_output_y_g(unit = "m") "Displacement of the output shaft's g relative to its pedestals' chord, y";
  Real r_output_y_e2(unit = "m") "Displacement of the output shaft's e2 relative to its pedestals' chord, y";
  Real q_output_y_e1(unit = "N") "Force of the output shaft's beam on its e1 (restoring, sign reversed), y";
  Real q_output_y_g(unit = "N") "Force of the output shaft's beam on its g (restoring, sign reversed), y";
  Real q_output_y_e2(unit = "N") "Force of the output shaft's beam on its e2 (restoring, sign reversed), y";
  Real force_x4(unit = "N") "Force of its shaft's beam on body 4, horizontal";
  Real force_x6(unit = "N") "Force of its shaft's beam on body 6, horizontal";
  Real force_x9(unit = "N") "Force of its shaft's beam on body 9, horizontal";
  Real force_x11(unit = "N") "Force of its shaft's beam on body 11, horizontal";
  Real force_x5(unit = "N") "Force of its shaft's beam on body 5, horizontal";
  Real force_x10(unit = "N") "Force of its shaft's beam on body 10, horizontal";
  Real force_y4(unit = "N") "Force of its shaft's beam on body 4, vertical";
  Real force_y6(unit = "N") "Force of its shaft's beam on body 6, vertical";
  Real force_y9(unit = "N") "Force of its shaft's beam on body 9, vertical";
  Real force_y11(unit = "N") "Force of its shaft's beam on body 11, vertical";
  Real force_y5(unit = "N") "Force of its shaft's beam on body 5, vertical";
  Real force_y10(unit = "N") "Force of its shaft's beam on body 10, vertical";
equation
  der(x_end4) = vx_end4;
  der(y_end4) = vy_end4;
  der(x_end6) = vx_end6;
  der(y_end6) = vy_end6;
  der(x_end9) = vx_end9;
  der(y_end9) = vy_end9;
  der(x_end11) = vx_end11;
  der(y_end11) = vy_end11;
  r_input_x_e1 = x_end4 - (span_input + overhang4) / span_input * x4 - (-overhang4 / span_input) * x6;
  r_input_x_g = x5 - (1 - pinion_position) * x4 - pinion_position * x6;
  r_input_x_e2 = x_end6 - (-overhang6 / span_input) * x4 - (span_input + overhang6) / span_input * x6;
  q_input_x_e1 = K_input_x_e1e1 * r_input_x_e1 + K_input_x_e1g * r_input_x_g + K_input_x_e1e2 * r_input_x_e2 + c_end4_x * (vx_end4 - (span_input + overhang4) / span_input * vx4 - (-overhang4 / span_input) * vx6);
  q_input_x_g = K_input_x_e1g * r_input_x_e1 + K_input_x_gg * r_input_x_g + K_input_x_ge2 * r_input_x_e2;
  q_input_x_e2 = K_input_x_e1e2 * r_input_x_e1 + K_input_x_ge2 * r_input_x_g + K_input_x_e2e2 * r_input_x_e2 + c_end6_x * (vx_end6 - (-overhang6 / span_input) * vx4 - (span_input + overhang6) / span_input * vx6);
  force_x5 = -q_input_x_g;
  force_x4 = (span_input + overhang4) / span_input * q_input_x_e1 + (1 - pinion_position) * q_input_x_g + (-overhang6 / span_input) * q_input_x_e2;
  force_x6 = (-overhang4 / span_input) * q_input_x_e1 + pinion_position * q_input_x_g + (span_input + overhang6) / span_input * q_input_x_e2;
  m_end4 * der(vx_end4) = -q_input_x_e1 - k_coupling_radial_input * x_end4;
  m_end6 * der(vx_end6) = -q_input_x_e2;
  r_input_y_e1 = y_end4 - (span_input + overhang4) / span_input * y4 - (-overhang4 / span_input) * y6;
  r_input_y_g = y5 - (1 - pinion_position) * y4 - pinion_position * y6;
  r_input_y_e2 = y_end6 - (-overhang6 / span_input) * y4 - (span_input + overhang6) / span_input * y6;
  q_input_y_e1 = K_input_y_e1e1 * r_input_y_e1 + K_input_y_e1g * r_input_y_g + K_input_y_e1e2 * r_input_y_e2 + c_end4_y * (vy_end4 - (span_input + overhang4) / span_input * vy4 - (-overhang4 / span_input) * vy6);
  q_input_y_g = K_input_y_e1g * r_input_y_e1 + K_input_y_gg * r_input_y_g + K_input_y_ge2 * r_input_y_e2;
  q_input_y_e2 = K_input_y_e1e2 * r_input_y_e1 + K_input_y_ge2 * r_input_y_g + K_input_y_e2e2 * r_input_y_e2 + c_end6_y * (vy_end6 - (-overhang6 / span_input) * vy4 - (span_input + overhang6) / span_input * vy6);
  force_y5 = -q_input_y_g;
  force_y4 = (span_input + overhang4) / span_input * q_input_y_e1 + (1 - pinion_position) * q_input_y_g + (-overhang6 / span_input) * q_input_y_e2;
  force_y6 = (-overhang4 / span_input) * q_input_y_e1 + pinion_position * q_input_y_g + (span_input + overhang6) / span_input * q_input_y_e2;
  m_end4 * der(vy_end4) = -q_input_y_e1 - k_coupling_radial_input * y_end4;
  m_end6 * der(vy_end6) = -q_input_y_e2;
  r_output_x_e1 = x_end9 - (span_output + overhang9) / span_output * x9 - (-overhang9 / span_output) * x11;
  r_output_x_g = x10 - (1 - gear_position) * x9 - gear_position * x11;
  r_output_x_e2 = x_end11 - (-overhang11 / span_output) * x9 - (span_output + overhang11) / span_output * x11;
  q_output_x_e1 = K_output_x_e1e1 * r_output_x_e1 + K_output_x_e1g * r_output_x_g + K_output_x_e1e2 * r_output_x_e2 + c_end9_x * (vx_end9 - (span_output + overhang9) / span_output * vx9 - (-overhang9 / span_output) * vx11);
  q_output_x_g = K_output_x_e1g * r_output_x_e1 + K_output_x_gg * r_output_x_g + K_output_x_ge2 * r_output_x_e2;
  q_output_x_e2 = K_output_x_e1e2 * r_output_x_e1 + K_output_x_ge2 * r_output_x_g + K_output_x_e2e2 * r_output_x_e2 + c_end11_x * (vx_end11 - (-overhang11 / span_output) * vx9 - (span_output + overhang11) / span_output * vx11);
  force_x10 = -q_output_x_g;
  force_x9 = (span_output + overhang9) / span_output * q_output_x_e1 + (1 - gear_position) * q_output_x_g + (-overhang11 / span_output) * q_output_x_e2;
  force_x11 = (-overhang9 / span_output) * q_output_x_e1 + gear_position * q_output_x_g + (span_output + overhang11) / span_output * q_output_x_e2;
  m_end9 * der(vx_end9) = -q_output_x_e1;
  m_end11 * der(vx_end11) = -q_output_x_e2 - k_coupling_radial_output * x_end11;
  r_output_y_e1 = y_end9 - (span_output + overhang9) / span_output * y9 - (-overhang9 / span_output) * y11;
  r_output_y_g = y10 - (1 - gear_position) * y9 - gear_position * y11;
  r_output_y_e2 = y_end11 - (-overhang11 / span_output) * y9 - (span_output + overhang11) / span_output * y11;
  q_output_y_e1 = K_output_y_e1e1 * r_output_y_e1 + K_output_y_e1g * r_output_y_g + K_output_y_e1e2 * r_output_y_e2 + c_end9_y * (vy_end9 - (span_output + overhang9) / span_output * vy9 - (-overhang9 / span_output) * vy11);
  q_output_y_g = K_output_y_e1g * r_output_y_e1 + K_output_y_gg * r_output_y_g + K_output_y_ge2 * r_output_y_e2;
  q_output_y_e2 = K_output_y_e1e2 * r_output_y_e1 + K_output_y_ge2 * r_output_y_g + K_output_y_e2e2 * r_output_y_e2 + c_end11_y * (vy_end11 - (-overhang11 / span_output) * vy9 - (span_output + overhang11) / span_output * vy11);
  force_y10 = -q_output_y_g;
  force_y9 = (span_output + overhang9) / span_output * q_output_y_e1 + (1 - gear_position) * q_output_y_g + (-overhang11 / span_output) * q_output_y_e2;
  force_y11 = (-overhang9 / span_output) * q_output_y_e1 + gear_position * q_output_y_g + (span_output + overhang11) / span_output * q_output_y_e2;
  m_end9 * der(vy_end9) = -q_output_y_e1;
  m_end11 * der(vy_end11) = -q_output_y_e2 - k_coupling_radial_output * y_end11;
end Gearbox21Overhangs;
