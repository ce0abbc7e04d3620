within GearTwin;
model Gearbox21Overhangs "GearTwin.Gearbox21Shafts with the parts the shafts carry outside their bearings (couplings, slip rings, encoders) moving sideways on the overhung shaft ends"
  // The paper's rig carries, outside the casing, a coupling half on the driven end of each shaft
  // (couplings 2 and 4) and a slip ring rotor, an adapter and a coupling to the encoder on each
  // free end (I7, I8). Its model keeps only their rotation. Sideways, each is a mass on a shaft
  // stub that overhangs its bearing by c, on a shaft whose bearings are L apart: a force F at the
  // end deflects it by
  //   F c^2 (L + c) / (3 E I)                                   (the stub and the span's slope)
  //   + F ((L + c) / L)^2 / k_near + F (c / L)^2 / k_far        (the two bearings, levered),
  // where k_near, k_far are the radial stiffnesses of the bearing beside the end and the other one.
  // Lumped: the end mass hangs on that spring from the pedestal of the bearing beside it, and
  // pushes it back. What is left out: the slope the gear's own deflection gives the shaft at the
  // bearings (a gear lateral mode swings the ends the other way); the shaft carries it only through
  // the pedestals here. A stub's own mass moves with its end by the cantilever's Rayleigh tip share
  // 33/140. The coupling halves are held sideways by their coupling to the motor or the brake
  // (elastomer jaw couplings: radial stiffness of order 1 kN/mm); the free ends are held by nothing
  // else (the slip ring's stator hangs on a torque arm).
  extends GearTwin.Gearbox21Shafts(
    overhang_force_x4 = k_end4_x * (x_end4 - x4) + c_end4_x * (vx_end4 - vx4),
    overhang_force_y4 = k_end4_y * (y_end4 - y4) + c_end4_y * (vy_end4 - vy4),
    overhang_force_x6 = k_end6_x * (x_end6 - x6) + c_end6_x * (vx_end6 - vx6),
    overhang_force_y6 = k_end6_y * (y_end6 - y6) + c_end6_y * (vy_end6 - vy6),
    overhang_force_x9 = k_end9_x * (x_end9 - x9) + c_end9_x * (vx_end9 - vx9),
    overhang_force_y9 = k_end9_y * (y_end9 - y9) + c_end9_y * (vy_end9 - vy9),
    overhang_force_x11 = k_end11_x * (x_end11 - x11) + c_end11_x * (vx_end11 - vx11),
    overhang_force_y11 = k_end11_y * (y_end11 - y11) + c_end11_y * (vy_end11 - vy11));
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
  parameter Real overhang_damping_ratio(min = 0) = 0.02 "Damping ratio of each end on its stub (shaft hysteresis, bearing and fits)";
  parameter Real tip_mass_share = 33 / 140 "Share of a stub's mass that moves with its end (Rayleigh, uniform cantilever)";
  // ---- Derived --------------------------------------------------------------------------------
  parameter Real bending_rigidity_input(unit = "N.m2") = shaft_youngs_modulus * GearTwin.pi * d_shaft_input ^ 4 / 64 "E I of the input shaft";
  parameter Real bending_rigidity_output(unit = "N.m2") = shaft_youngs_modulus * GearTwin.pi * d_shaft_output ^ 4 / 64 "E I of the output shaft";
  parameter Real m_end4(unit = "kg") = end_mass4 + tip_mass_share * shaft_density * GearTwin.pi * d_shaft_input ^ 2 / 4 * overhang4 "Mass moving with the input shaft's motor-side end";
  parameter Real m_end6(unit = "kg") = end_mass6 + tip_mass_share * shaft_density * GearTwin.pi * d_shaft_input ^ 2 / 4 * overhang6 "Mass moving with the input shaft's free end";
  parameter Real m_end9(unit = "kg") = end_mass9 + tip_mass_share * shaft_density * GearTwin.pi * d_shaft_output ^ 2 / 4 * overhang9 "Mass moving with the output shaft's free end";
  parameter Real m_end11(unit = "kg") = end_mass11 + tip_mass_share * shaft_density * GearTwin.pi * d_shaft_output ^ 2 / 4 * overhang11 "Mass moving with the output shaft's brake-side end";
  parameter Real k_end4_x(unit = "N/m") = 1 / (overhang4 ^ 2 * (span_input + overhang4) / (3 * bending_rigidity_input) + ((span_input + overhang4) / span_input) ^ 2 / kx_bearing4 + (overhang4 / span_input) ^ 2 / kx_bearing6) "Stub and bearings under the input shaft's motor-side end, horizontal";
  parameter Real k_end4_y(unit = "N/m") = 1 / (overhang4 ^ 2 * (span_input + overhang4) / (3 * bending_rigidity_input) + ((span_input + overhang4) / span_input) ^ 2 / ky_bearing4 + (overhang4 / span_input) ^ 2 / ky_bearing6) "Stub and bearings under the input shaft's motor-side end, vertical";
  parameter Real k_end6_x(unit = "N/m") = 1 / (overhang6 ^ 2 * (span_input + overhang6) / (3 * bending_rigidity_input) + ((span_input + overhang6) / span_input) ^ 2 / kx_bearing6 + (overhang6 / span_input) ^ 2 / kx_bearing4) "Stub and bearings under the input shaft's free end, horizontal";
  parameter Real k_end6_y(unit = "N/m") = 1 / (overhang6 ^ 2 * (span_input + overhang6) / (3 * bending_rigidity_input) + ((span_input + overhang6) / span_input) ^ 2 / ky_bearing6 + (overhang6 / span_input) ^ 2 / ky_bearing4) "Stub and bearings under the input shaft's free end, vertical";
  parameter Real k_end9_x(unit = "N/m") = 1 / (overhang9 ^ 2 * (span_output + overhang9) / (3 * bending_rigidity_output) + ((span_output + overhang9) / span_output) ^ 2 / kx_bearing9 + (overhang9 / span_output) ^ 2 / kx_bearing11) "Stub and bearings under the output shaft's free end, horizontal";
  parameter Real k_end9_y(unit = "N/m") = 1 / (overhang9 ^ 2 * (span_output + overhang9) / (3 * bending_rigidity_output) + ((span_output + overhang9) / span_output) ^ 2 / ky_bearing9 + (overhang9 / span_output) ^ 2 / ky_bearing11) "Stub and bearings under the output shaft's free end, vertical";
  parameter Real k_end11_x(unit = "N/m") = 1 / (overhang11 ^ 2 * (span_output + overhang11) / (3 * bending_rigidity_output) + ((span_output + overhang11) / span_output) ^ 2 / kx_bearing11 + (overhang11 / span_output) ^ 2 / kx_bearing9) "Stub and bearings under the output shaft's brake-side end, horizontal";
  parameter Real k_end11_y(unit = "N/m") = 1 / (overhang11 ^ 2 * (span_output + overhang11) / (3 * bending_rigidity_output) + ((span_output + overhang11) / span_output) ^ 2 / ky_bearing11 + (overhang11 / span_output) ^ 2 / ky_bearing9) "Stub and bearings under the output shaft's brake-side end, vertical";
  parameter Real c_end4_x(unit = "N.s/m") = 2 * overhang_damping_ratio * sqrt(k_end4_x * m_end4) "Damping of the motor-side end, horizontal";
  parameter Real c_end4_y(unit = "N.s/m") = 2 * overhang_damping_ratio * sqrt(k_end4_y * m_end4) "Damping of the motor-side end, vertical";
  parameter Real c_end6_x(unit = "N.s/m") = 2 * overhang_damping_ratio * sqrt(k_end6_x * m_end6) "Damping of the input shaft's free end, horizontal";
  parameter Real c_end6_y(unit = "N.s/m") = 2 * overhang_damping_ratio * sqrt(k_end6_y * m_end6) "Damping of the input shaft's free end, vertical";
  parameter Real c_end9_x(unit = "N.s/m") = 2 * overhang_damping_ratio * sqrt(k_end9_x * m_end9) "Damping of the output shaft's free end, horizontal";
  parameter Real c_end9_y(unit = "N.s/m") = 2 * overhang_damping_ratio * sqrt(k_end9_y * m_end9) "Damping of the output shaft's free end, vertical";
  parameter Real c_end11_x(unit = "N.s/m") = 2 * overhang_damping_ratio * sqrt(k_end11_x * m_end11) "Damping of the brake-side end, horizontal";
  parameter Real c_end11_y(unit = "N.s/m") = 2 * overhang_damping_ratio * sqrt(k_end11_y * m_end11) "Damping of the brake-side end, vertical";
  // ---- States of the four ends ----------------------------------------------------------------
  Real x_end4(unit = "m", start = 0.0, fixed = true, nominal = 1e-6) "Horizontal displacement of the input shaft's motor-side end";
  Real y_end4(unit = "m", start = 0.0, fixed = true, nominal = 1e-6) "Vertical displacement of the input shaft's motor-side end";
  Real x_end6(unit = "m", start = 0.0, fixed = true, nominal = 1e-6) "Horizontal displacement of the input shaft's free end";
  Real y_end6(unit = "m", start = 0.0, fixed = true, nominal = 1e-6) "Vertical displacement of the input shaft's free end";
  Real x_end9(unit = "m", start = 0.0, fixed = true, nominal = 1e-6) "Horizontal displacement of the output shaft's free end";
  Real y_end9(unit = "m", start = 0.0, fixed = true, nominal = 1e-6) "Vertical displacement of the output shaft's free end";
  Real x_end11(unit = "m", start = 0.0, fixed = true, nominal = 1e-6) "Horizontal displacement of the output shaft's brake-side end";
  Real y_end11(unit = "m", start = 0.0, fixed = true, nominal = 1e-6) "Vertical displacement of the output shaft's brake-side end";
  Real vx_end4(unit = "m/s", start = 0.0, fixed = true, nominal = 1e-3) "Horizontal velocity of the input shaft's motor-side end";
  Real vy_end4(unit = "m/s", start = 0.0, fixed = true, nominal = 1e-3) "Vertical velocity of the input shaft's motor-side end";
  Real vx_end6(unit = "m/s", start = 0.0, fixed = true, nominal = 1e-3) "Horizontal velocity of the input shaft's free end";
  Real vy_end6(unit = "m/s", start = 0.0, fixed = true, nominal = 1e-3) "Vertical velocity of the input shaft's free end";
  Real vx_end9(unit = "m/s", start = 0.0, fixed = true, nominal = 1e-3) "Horizontal velocity of the output shaft's free end";
  Real vy_end9(unit = "m/s", start = 0.0, fixed = true, nominal = 1e-3) "Vertical velocity of the output shaft's free end";
  Real vx_end11(unit = "m/s", start = 0.0, fixed = true, nominal = 1e-3) "Horizontal velocity of the output shaft's brake-side end";
  Real vy_end11(unit = "m/s", start = 0.0, fixed = true, nominal = 1e-3) "Vertical velocity of the output shaft's brake-side end";
equation
  der(x_end4) = vx_end4;
  der(y_end4) = vy_end4;
  der(x_end6) = vx_end6;
  der(y_end6) = vy_end6;
  der(x_end9) = vx_end9;
  der(y_end9) = vy_end9;
  der(x_end11) = vx_end11;
  der(y_end11) = vy_end11;
  m_end4 * der(vx_end4) = -overhang_force_x4 - k_coupling_radial_input * x_end4;
  m_end4 * der(vy_end4) = -overhang_force_y4 - k_coupling_radial_input * y_end4;
  m_end6 * der(vx_end6) = -overhang_force_x6;
  m_end6 * der(vy_end6) = -overhang_force_y6;
  m_end9 * der(vx_end9) = -overhang_force_x9;
  m_end9 * der(vy_end9) = -overhang_force_y9;
  m_end11 * der(vx_end11) = -overhang_force_x11 - k_coupling_radial_output * x_end11;
  m_end11 * der(vy_end11) = -overhang_force_y11 - k_coupling_radial_output * y_end11;
end Gearbox21Overhangs;
