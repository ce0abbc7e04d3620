within GearTwin;
model Gearbox21 "21-DOF lumped model of the UNSW spur-gear test rig (Feng et al., Fig. 3, Tables A1-A2)"
  // Torsional chain (9 DOF): motor 1 - torque meter 2 - input coupling 3 - pinion 5 - slip ring 7,
  // slip ring 8 - gear 10 - output coupling 12 - brake 13. Angles of the gear side are counted
  // positive in the driven direction, so the mesh kinematics read rb1*theta5 = rb2*theta10.
  // Lateral (12 DOF): pedestals 4, 6 (input shaft), pinion 5, pedestals 9, 11 (output shaft), gear 10.

  // ---- Gear geometry -------------------------------------------------------------------------
  parameter Integer z1 = 19 "Number of pinion teeth (structural: sizes the per-tooth arrays)";
  parameter Integer z2 = 52 "Number of gear teeth (structural: sets the geometry the built-in mesh stiffness is computed for)";
  parameter Real module(unit = "m", min = 0) = 3.0e-3 "Normal module";
  parameter Real alpha(unit = "rad", min = 0, max = GearTwin.pi / 2) = 20 * GearTwin.pi / 180 "Pressure angle";
  parameter Real face_width(unit = "m", min = 0) = 0.020 "Face width (stated assumption)";
  parameter Real addendum_coefficient(min = 0) = 1.0 "Addendum as a multiple of the module";
  parameter Real rb1(unit = "m", min = 0) = 0.5 * module * z1 * cos(alpha) "Pinion base radius";
  parameter Real rb2(unit = "m", min = 0) = 0.5 * module * z2 * cos(alpha) "Gear base radius";
  parameter Real contact_ratio(min = 0) = (sqrt((0.5 * module * z1 + addendum_coefficient * module) ^ 2 - rb1 ^ 2) + sqrt((0.5 * module * z2 + addendum_coefficient * module) ^ 2 - rb2 ^ 2) - 0.5 * module * (z1 + z2) * sin(alpha)) / (GearTwin.pi * module * cos(alpha)) "Transverse contact ratio";
  parameter Real line_of_action_length(unit = "m", min = 0) = 0.5 * module * (z1 + z2) * sin(alpha) "Distance T1-T2 between the points where the line of action touches the base circles";
  parameter Real contact_path_length(unit = "m", min = 0) = contact_ratio * GearTwin.pi * module * cos(alpha) "Length of the path of contact";
  parameter Real contact_start_radius(unit = "m") = line_of_action_length - sqrt((0.5 * module * z2 + addendum_coefficient * module) ^ 2 - rb2 ^ 2) "Distance from T1 to the start of contact (curvature radius of the pinion flank there)";
  parameter Real roll_pitch = (0.5 * module * z1 * sin(alpha) - contact_start_radius) / contact_path_length "Roll position of the pitch point, where sliding reverses (0 = start, 1 = end of contact)";

  // ---- Mesh stiffness and profile (tunable; the degradation models write these) -------------
  parameter Integer n_profile = 11 "Number of nodes along the path of contact (structural)";
  parameter Real k_pair[n_profile](each unit = "N/m", each min = 0, each nominal = 1e8) = {1.650e8 + 1.350e8 * (1 - (2 * (n - 1) / (n_profile - 1) - 1) ^ 2) for n in 1:n_profile} "Single-tooth-pair stiffness at equally spaced roll positions from start (root of pinion) to end (tip of pinion) of the path of contact";
  parameter Real profile_deviation[n_profile](each unit = "m", each nominal = 1e-6) = fill(0.0, n_profile) "Material missing from the pinion flank (wear depth, relief) at the same nodes, common to all teeth";
  parameter Real tooth_stiffness_factor[z1] = fill(1.0, z1) "Per-pinion-tooth multiplier of the pair stiffness (crack, spall, pitting of one tooth)";
  parameter Real tooth_deviation_offset[z1](each unit = "m") = fill(0.0, z1) "Per-pinion-tooth extra material loss, added to profile_deviation";
  parameter Real tooth_pit_field[z1 * n_profile](each unit = "m", each nominal = 1e-6) = fill(0.0, z1 * n_profile) "Equivalent material loss of each pinion tooth at the profile nodes beyond the common profile, tooth-major: element (j - 1) * n_profile + n is tooth j at node n (pits at different places on different teeth; uneven wear)";
  parameter Real mesh_stiffness_scale(min = 0) = 1.0 "Calibration multiplier of all pair stiffnesses";
  parameter Real c_mesh(unit = "N.s/m", min = 0) = 1.1e3 "Mesh damping along the line of action";
  parameter Real contact_damping_width(unit = "m", min = 0) = 1e-8 "Approach over which the mesh damping engages when the flanks touch";
  parameter Real lead_mismatch(unit = "m") = 0 "Lead mismatch of the flanks across the face (misalignment): the gap at one face end while the other touches";
  parameter Real mesh_phase0(unit = "rad") = 0.0 "Mesh phase at theta5 = 0";
  parameter Real contact_smoothing = 0.01 "Half-width of the entry/exit ramp of a tooth pair, as a fraction of the path of contact";

  // ---- Inertias and masses (Table A1; values are stated assumptions) -------------------------
  parameter Real I1(unit = "kg.m2", min = 0) = 4.3e-3 "Motor, motor shaft, 1/2 coupling 1";
  parameter Real I2(unit = "kg.m2", min = 0) = 4.0e-4 "1/2 coupling 1, 1/2 coupling 2, torque-meter shaft";
  parameter Real I3(unit = "kg.m2", min = 0) = 3.0e-4 "1/2 coupling 2, input shaft to bearing";
  parameter Real I5(unit = "kg.m2", min = 0) = 2.5e-4 "Pinion and input shaft through casing";
  parameter Real I7(unit = "kg.m2", min = 0) = 5.0e-4 "Slip ring rotor, adapter, coupling 3, free shaft end (input)";
  parameter Real I8(unit = "kg.m2", min = 0) = 5.0e-4 "Slip ring rotor, adapter, coupling 5, free shaft end (output)";
  parameter Real I10(unit = "kg.m2", min = 0) = 9.5e-3 "Gear and output shaft through casing";
  parameter Real I12(unit = "kg.m2", min = 0) = 5.0e-4 "1/2 coupling 4, output shaft to bearing";
  parameter Real I13(unit = "kg.m2", min = 0) = 2.0e-2 "Brake, brake shaft, 1/2 coupling 4";
  parameter Real m4(unit = "kg", min = 0) = 2.0 "Pedestal and bearing 4 (input shaft, motor side)";
  parameter Real m5(unit = "kg", min = 0) = 0.6 "Pinion";
  parameter Real m6(unit = "kg", min = 0) = 2.0 "Pedestal and bearing 6 (input shaft, free end)";
  parameter Real m9(unit = "kg", min = 0) = 2.0 "Pedestal and bearing 9 (output shaft, free end)";
  parameter Real m10(unit = "kg", min = 0) = 3.5 "Gear";
  parameter Real m11(unit = "kg", min = 0) = 2.0 "Pedestal and bearing 11 (output shaft, brake side)";

  // ---- Stiffness and damping (Table A2; values are stated assumptions) -----------------------
  parameter Real kt12(unit = "N.m/rad", min = 0) = 1.5e3 "Coupling 1";
  parameter Real kt23(unit = "N.m/rad", min = 0) = 2.0e3 "Coupling 2";
  parameter Real kt35(unit = "N.m/rad", min = 0) = 1.5e4 "Input shaft, coupling 2 to pinion";
  parameter Real kt57(unit = "N.m/rad", min = 0) = 1.5e4 "Input shaft, pinion to slip ring";
  parameter Real kt810(unit = "N.m/rad", min = 0) = 2.0e4 "Output shaft, slip ring to gear";
  parameter Real kt1012(unit = "N.m/rad", min = 0) = 2.0e4 "Output shaft, gear to coupling 4";
  parameter Real kt1213(unit = "N.m/rad", min = 0) = 1.5e3 "Coupling 4";
  parameter Real ct12(unit = "N.m.s/rad", min = 0) = 0.10 "Coupling 1";
  parameter Real ct23(unit = "N.m.s/rad", min = 0) = 0.10 "Coupling 2";
  parameter Real ct35(unit = "N.m.s/rad", min = 0) = 0.08 "Input shaft, coupling 2 to pinion";
  parameter Real ct57(unit = "N.m.s/rad", min = 0) = 0.08 "Input shaft, pinion to slip ring";
  parameter Real ct810(unit = "N.m.s/rad", min = 0) = 0.10 "Output shaft, slip ring to gear";
  parameter Real ct1012(unit = "N.m.s/rad", min = 0) = 0.10 "Output shaft, gear to coupling 4";
  parameter Real ct1213(unit = "N.m.s/rad", min = 0) = 0.10 "Coupling 4";
  parameter Real kx45(unit = "N/m", min = 0) = 1.0e8 "Input shaft and bearing between 4 and 5, horizontal";
  parameter Real ky45(unit = "N/m", min = 0) = 1.0e8 "Input shaft and bearing between 4 and 5, vertical";
  parameter Real kx56(unit = "N/m", min = 0) = 1.0e8 "Input shaft and bearing between 5 and 6, horizontal";
  parameter Real ky56(unit = "N/m", min = 0) = 1.0e8 "Input shaft and bearing between 5 and 6, vertical";
  parameter Real kx910(unit = "N/m", min = 0) = 1.5e8 "Output shaft and bearing between 9 and 10, horizontal";
  parameter Real ky910(unit = "N/m", min = 0) = 1.5e8 "Output shaft and bearing between 9 and 10, vertical";
  parameter Real kx1011(unit = "N/m", min = 0) = 1.5e8 "Output shaft and bearing between 10 and 11, horizontal";
  parameter Real ky1011(unit = "N/m", min = 0) = 1.5e8 "Output shaft and bearing between 10 and 11, vertical";
  parameter Real cx45(unit = "N.s/m", min = 0) = 400 "Damping 4-5, horizontal";
  parameter Real cy45(unit = "N.s/m", min = 0) = 400 "Damping 4-5, vertical";
  parameter Real cx56(unit = "N.s/m", min = 0) = 400 "Damping 5-6, horizontal";
  parameter Real cy56(unit = "N.s/m", min = 0) = 400 "Damping 5-6, vertical";
  parameter Real cx910(unit = "N.s/m", min = 0) = 500 "Damping 9-10, horizontal";
  parameter Real cy910(unit = "N.s/m", min = 0) = 500 "Damping 9-10, vertical";
  parameter Real cx1011(unit = "N.s/m", min = 0) = 500 "Damping 10-11, horizontal";
  parameter Real cy1011(unit = "N.s/m", min = 0) = 500 "Damping 10-11, vertical";
  parameter Real kx4(unit = "N/m", min = 0) = 3.0e7 "Pedestal 4 to ground, horizontal (not in Table A2; needed to remove the free mode)";
  parameter Real ky4(unit = "N/m", min = 0) = 5.0e7 "Pedestal 4 to ground, vertical";
  parameter Real kx6(unit = "N/m", min = 0) = 3.0e7 "Pedestal 6 to ground, horizontal";
  parameter Real ky6(unit = "N/m", min = 0) = 5.0e7 "Pedestal 6 to ground, vertical";
  parameter Real kx9(unit = "N/m", min = 0) = 3.0e7 "Pedestal 9 to ground, horizontal";
  parameter Real ky9(unit = "N/m", min = 0) = 5.0e7 "Pedestal 9 to ground, vertical";
  parameter Real kx11(unit = "N/m", min = 0) = 3.0e7 "Pedestal 11 to ground, horizontal";
  parameter Real ky11(unit = "N/m", min = 0) = 5.0e7 "Pedestal 11 to ground, vertical";
  parameter Real cx4(unit = "N.s/m", min = 0) = 400 "Pedestal 4 damping, horizontal";
  parameter Real cy4(unit = "N.s/m", min = 0) = 400 "Pedestal 4 damping, vertical";
  parameter Real cx6(unit = "N.s/m", min = 0) = 400 "Pedestal 6 damping, horizontal";
  parameter Real cy6(unit = "N.s/m", min = 0) = 400 "Pedestal 6 damping, vertical";
  parameter Real cx9(unit = "N.s/m", min = 0) = 400 "Pedestal 9 damping, horizontal";
  parameter Real cy9(unit = "N.s/m", min = 0) = 400 "Pedestal 9 damping, vertical";
  parameter Real cx11(unit = "N.s/m", min = 0) = 400 "Pedestal 11 damping, horizontal";
  parameter Real cy11(unit = "N.s/m", min = 0) = 400 "Pedestal 11 damping, vertical";

  // ---- Drive, load and sensors ---------------------------------------------------------------
  parameter Real c_motor(unit = "N.m.s/rad", min = 0) = 3.0 "Slope of the induction motor torque-slip line (VFD speed control)";
  parameter Real sensor_angle_pinion(unit = "rad") = 0.0 "Axis of the B&K 4396 accelerometer (0 = vertical, pi/2 = horizontal)";
  parameter Real sensor_angle_gear(unit = "rad") = 0.0 "Axis of the B&K 4394 accelerometer (0 = vertical, pi/2 = horizontal)";
  parameter Real speed_ref_start(unit = "rad/s") = 2 * GearTwin.pi * 20 "Commanded motor speed assumed for the steady start";
  parameter Real load_start(unit = "N.m") = 20.0 "Brake torque used for the static pre-load at t = 0";

  input Real motor_speed_ref(unit = "rad/s", start = 2 * GearTwin.pi * 20) "Synchronous speed commanded by the drive";
  input Real drive_torque(unit = "N.m", start = 0.0) "Extra motor torque added to the slip torque";
  input Real load_torque(unit = "N.m", start = 20.0) "Brake torque on the output shaft";

  // Static pre-load so a run starts near steady running: torque transmitted by each shaft.
  parameter Real torque_out(unit = "N.m") = load_start "Static torque in the output chain";
  parameter Real torque_in(unit = "N.m") = load_start * rb1 / rb2 "Static torque in the input chain";
  parameter Real mesh_force_static(unit = "N") = torque_in / rb1 "Static mesh force";
  // Hertzian contact of the static mesh force on one pair at the pitch point (both gears steel):
  // its width sets how short a roughness wavelength still reaches the mesh (GearTwin.Excitation).
  parameter Real gear_youngs_modulus(unit = "Pa", min = 1e8) = 2.06e11 "Young's modulus of the gears' steel (the build option youngs_modulus sets it and the computed mesh stiffness alike)";
  parameter Real gear_poisson_ratio(min = 0, max = 0.5) = 0.3 "Poisson's ratio of the gears' steel (build option poisson_ratio)";
  parameter Real pitch_curvature_pinion(unit = "m", min = 0) = 0.5 * module * z1 * sin(alpha) "Radius of curvature of the pinion flank at the pitch point";
  parameter Real pitch_curvature_gear(unit = "m", min = 0) = 0.5 * module * z2 * sin(alpha) "Radius of curvature of the gear flank at the pitch point";
  parameter Real hertz_half_width(unit = "m", min = 0) = sqrt(8 * max(mesh_force_static, 0) / face_width * (pitch_curvature_pinion * pitch_curvature_gear / (pitch_curvature_pinion + pitch_curvature_gear)) * (1 - gear_poisson_ratio ^ 2) / (GearTwin.pi * gear_youngs_modulus)) "Hertzian half-width of the static mesh force on one pair at the pitch point (line contact)";
  parameter Real speed_start(unit = "rad/s") = speed_ref_start - torque_in / c_motor "Motor speed at t = 0 (steady slip under the static load)";
  parameter Real k_mesh_mean(unit = "N/m", min = 0, nominal = 1e8) = mesh_stiffness_scale * contact_ratio * sum(k_pair) / n_profile "Approximate mean mesh stiffness";

  // ---- States ----------------------------------------------------------------------------------
  Real theta1(unit = "rad", start = 0.0, fixed = true) "Rotation angle of the motor";
  Real theta2(unit = "rad", start = -torque_in / kt12, fixed = true) "Rotation angle of the torque meter";
  Real theta3(unit = "rad", start = -torque_in / kt12 - torque_in / kt23, fixed = true) "Rotation angle of the input coupling";
  Real theta5(unit = "rad", start = -torque_in / kt12 - torque_in / kt23 - torque_in / kt35, fixed = true) "Rotation angle of the pinion";
  Real theta7(unit = "rad", start = -torque_in / kt12 - torque_in / kt23 - torque_in / kt35, fixed = true) "Rotation angle of the input slip ring and encoder (input shaft, free end)";
  Real theta10(unit = "rad", start = (rb1 * (-torque_in / kt12 - torque_in / kt23 - torque_in / kt35) - mesh_force_static / k_mesh_mean) / rb2, fixed = true) "Rotation angle of the gear";
  Real theta8(unit = "rad", start = (rb1 * (-torque_in / kt12 - torque_in / kt23 - torque_in / kt35) - mesh_force_static / k_mesh_mean) / rb2, fixed = true) "Rotation angle of the output slip ring and encoder (output shaft, free end)";
  Real theta12(unit = "rad", start = (rb1 * (-torque_in / kt12 - torque_in / kt23 - torque_in / kt35) - mesh_force_static / k_mesh_mean) / rb2 - torque_out / kt1012, fixed = true) "Rotation angle of the output coupling";
  Real theta13(unit = "rad", start = (rb1 * (-torque_in / kt12 - torque_in / kt23 - torque_in / kt35) - mesh_force_static / k_mesh_mean) / rb2 - torque_out / kt1012 - torque_out / kt1213, fixed = true) "Rotation angle of the brake";
  Real omega1(unit = "rad/s", start = speed_start, fixed = true, nominal = 100) "Angular speed of the motor";
  Real omega2(unit = "rad/s", start = speed_start, fixed = true, nominal = 100) "Angular speed of the torque meter";
  Real omega3(unit = "rad/s", start = speed_start, fixed = true, nominal = 100) "Angular speed of the input coupling";
  Real omega5(unit = "rad/s", start = speed_start, fixed = true, nominal = 100) "Angular speed of the pinion";
  Real omega7(unit = "rad/s", start = speed_start, fixed = true, nominal = 100) "Angular speed of the input slip ring and encoder (input shaft, free end)";
  Real omega8(unit = "rad/s", start = speed_start * rb1 / rb2, fixed = true, nominal = 100) "Angular speed of the output slip ring and encoder (output shaft, free end)";
  Real omega10(unit = "rad/s", start = speed_start * rb1 / rb2, fixed = true, nominal = 100) "Angular speed of the gear";
  Real omega12(unit = "rad/s", start = speed_start * rb1 / rb2, fixed = true, nominal = 100) "Angular speed of the output coupling";
  Real omega13(unit = "rad/s", start = speed_start * rb1 / rb2, fixed = true, nominal = 100) "Angular speed of the brake";
  Real x4(unit = "m", start = 0.0, fixed = true, nominal = 1e-6) "Horizontal displacement of the pedestal 4 (input shaft, motor side)";
  Real y4(unit = "m", start = 0.0, fixed = true, nominal = 1e-6) "Vertical displacement of the pedestal 4 (input shaft, motor side)";
  Real x5(unit = "m", start = 0.0, fixed = true, nominal = 1e-6) "Horizontal displacement of the pinion";
  Real y5(unit = "m", start = 0.0, fixed = true, nominal = 1e-6) "Vertical displacement of the pinion";
  Real x6(unit = "m", start = 0.0, fixed = true, nominal = 1e-6) "Horizontal displacement of the pedestal 6 (input shaft, free end)";
  Real y6(unit = "m", start = 0.0, fixed = true, nominal = 1e-6) "Vertical displacement of the pedestal 6 (input shaft, free end)";
  Real x9(unit = "m", start = 0.0, fixed = true, nominal = 1e-6) "Horizontal displacement of the pedestal 9 (output shaft, free end)";
  Real y9(unit = "m", start = 0.0, fixed = true, nominal = 1e-6) "Vertical displacement of the pedestal 9 (output shaft, free end)";
  Real x10(unit = "m", start = 0.0, fixed = true, nominal = 1e-6) "Horizontal displacement of the gear";
  Real y10(unit = "m", start = 0.0, fixed = true, nominal = 1e-6) "Vertical displacement of the gear";
  Real x11(unit = "m", start = 0.0, fixed = true, nominal = 1e-6) "Horizontal displacement of the pedestal 11 (output shaft, brake side)";
  Real y11(unit = "m", start = 0.0, fixed = true, nominal = 1e-6) "Vertical displacement of the pedestal 11 (output shaft, brake side)";
  Real vx4(unit = "m/s", start = 0.0, fixed = true, nominal = 1e-3) "Horizontal velocity of the pedestal 4 (input shaft, motor side)";
  Real vy4(unit = "m/s", start = 0.0, fixed = true, nominal = 1e-3) "Vertical velocity of the pedestal 4 (input shaft, motor side)";
  Real vx5(unit = "m/s", start = 0.0, fixed = true, nominal = 1e-3) "Horizontal velocity of the pinion";
  Real vy5(unit = "m/s", start = 0.0, fixed = true, nominal = 1e-3) "Vertical velocity of the pinion";
  Real vx6(unit = "m/s", start = 0.0, fixed = true, nominal = 1e-3) "Horizontal velocity of the pedestal 6 (input shaft, free end)";
  Real vy6(unit = "m/s", start = 0.0, fixed = true, nominal = 1e-3) "Vertical velocity of the pedestal 6 (input shaft, free end)";
  Real vx9(unit = "m/s", start = 0.0, fixed = true, nominal = 1e-3) "Horizontal velocity of the pedestal 9 (output shaft, free end)";
  Real vy9(unit = "m/s", start = 0.0, fixed = true, nominal = 1e-3) "Vertical velocity of the pedestal 9 (output shaft, free end)";
  Real vx10(unit = "m/s", start = 0.0, fixed = true, nominal = 1e-3) "Horizontal velocity of the gear";
  Real vy10(unit = "m/s", start = 0.0, fixed = true, nominal = 1e-3) "Vertical velocity of the gear";
  Real vx11(unit = "m/s", start = 0.0, fixed = true, nominal = 1e-3) "Horizontal velocity of the pedestal 11 (output shaft, brake side)";
  Real vy11(unit = "m/s", start = 0.0, fixed = true, nominal = 1e-3) "Vertical velocity of the pedestal 11 (output shaft, brake side)";

  // ---- Mesh kinematics -------------------------------------------------------------------------
  Real mesh_angle(unit = "rad") "Mesh phase: z1 * theta5 + mesh_phase0";
  Real cycle_fraction "Position within the current mesh cycle, (0, 1]";
  Real tooth_angle(unit = "rad") "Angle 2*pi*k/z1 of the pinion tooth that entered contact last (k = completed mesh cycles)";
  output Real roll[3] "Roll position along the path of contact (0 = start, 1 = end) of the pairs leading, current and next";
  Real window[3] "Share of each pair in contact (smooth 0-1 gate over [0, 1])";
  Real pair_tooth[3] "Pinion tooth (1..z1, integer valued) in each pair: mod(k - 1, z1) + 1, mod(k, z1) + 1, mod(k + 1, z1) + 1 with k = completed mesh cycles";
  Real profile_position[3] "Contact point of each pair in node spacings from the start of the path of contact (0..n_profile - 1)";
  Real pair_node[3] "Profile interval of each pair's contact point (0..n_profile - 2, integer valued): it lies between nodes pair_node + 1 and pair_node + 2";
  Real pair_tooth_factor[3] "tooth_stiffness_factor of the pinion tooth in each pair";
  Real pair_tooth_offset[3](each unit = "m") "tooth_deviation_offset of the pinion tooth in each pair";
  Real pair_pit_field[3](each unit = "m") "tooth_pit_field of the pinion tooth in each pair, interpolated at its contact point";
  Real pair_stiffness[3](each unit = "N/m") "Stiffness of each tooth pair";
  Real pair_deviation[3](each unit = "m") "Profile deviation at the contact point of each pair";
  output Real pair_force[3](each unit = "N", each min = 0) "Elastic force carried by each pair";
  Real face_mismatch(unit = "m", min = 0) "Lead mismatch across the face in force: |lead_mismatch + effect_lead_mismatch|";
  Real mesh_deflection(unit = "m") "Approach of the flanks along the line of action";
  Real mesh_deflection_rate(unit = "m/s") "Time derivative of mesh_deflection";
  output Real mesh_force(unit = "N") "Dynamic mesh force along the line of action";
  Real mesh_contact "Share of the mesh damping that acts: 1 while a pair of flanks touches, 0 while they are apart";
  output Real mesh_stiffness(unit = "N/m", min = 0) "Instantaneous mesh stiffness (sum over pairs in contact)";
  output Real accel_pinion_casing(unit = "m/s2") "Casing acceleration at the B&K 4396 (near the pinion)";
  output Real accel_gear_casing(unit = "m/s2") "Casing acceleration at the B&K 4394 (near the gear)";
  output Real encoder_pinion_angle(unit = "rad") = theta7 "Input-shaft encoder angle (free end)";
  output Real encoder_gear_angle(unit = "rad") = theta8 "Output-shaft encoder angle (free end)";
  output Real transmission_error(unit = "m") "rb1*theta5 - rb2*theta10 along the line of action";
  output Real motor_speed(unit = "rad/s") = omega1 "Motor speed";
  output Real motor_torque(unit = "N.m") "Torque delivered by the motor";
  Real casing_acceleration_pinion(unit = "m/s2") "Acceleration of pedestal 6 along the pinion sensor axis";

  // ---- Effect hooks ----------------------------------------------------------------------------
  // Neutral in this model (zero; one for the stiffness multiplier). A variant written by
  // `twin add-effect` (or by hand, see
  // GearTwin/Effects/README.md) extends this model and binds a hook to the output of an effect
  // component from GearTwin.Effects, e.g. extends Gearbox21(effect_drive_torque = ripple.torque).
  parameter Real effect_tooth_stiffness_factor[z1] = fill(1.0, z1) "Per-pinion-tooth stiffness multiplier from an effect (local tooth damage); multiplies tooth_stiffness_factor";
  parameter Real effect_tooth_offset[z1](each unit = "m") = fill(0.0, z1) "Per-pinion-tooth material loss from an effect (spall); added to tooth_deviation_offset";
  parameter Real effect_profile_deviation[n_profile](each unit = "m") = fill(0.0, n_profile) "Material missing along the profile from an effect (distributed wear); added to profile_deviation";
  Real effect_pair_deviation[3](each unit = "m") = {0, 0, 0} "Extra material loss at the contact of each pair (leading, current, next): the gear's tooth errors (GearTwin.Variants.Gearbox21WheelErrors); added to pair_deviation";
  Real effect_mesh_displacement(unit = "m") = 0 "Rigid move of a gear along the line of action (run-out): extra approach of the flanks, and contact starting that much earlier along the path";
  Real effect_mesh_displacement_rate(unit = "m/s") = 0 "Time derivative of effect_mesh_displacement";
  Real effect_off_line_displacement(unit = "m") = 0 "Rigid move of a gear normal to the line of action in the plane of the gears (run-out), positive where the centre distance shrinks: contact starts effect_off_line_displacement / tan(alpha) earlier along the path";
  Real effect_lead_mismatch(unit = "m") = 0 "Extra lead mismatch across the face (the wobble of a gear tilted on its shaft); added to lead_mismatch";
  Real effect_mesh_force(unit = "N") = 0 "Extra force along the line of action (back-flank contact)";
  Real effect_drive_torque(unit = "N.m") = 0 "Extra motor torque (torque ripple)";
  Real effect_load_torque(unit = "N.m") = 0 "Extra brake torque (load fluctuation)";
  Real effect_pinion_torque(unit = "N.m") = 0 "Extra torque on the pinion (tooth friction)";
  Real effect_gear_torque(unit = "N.m") = 0 "Extra torque on the gear, driven direction positive (tooth friction)";
  Real effect_off_line_force(unit = "N") = 0 "Force on the pinion across the line of action, along (cos alpha, -sin alpha); the gear takes the reaction (tooth friction)";
  Real effect_sensor_acceleration_pinion(unit = "m/s2") = 0 "Extra acceleration seen by the pinion-side sensor (casing panel or sensor-mount mode)";
  // Broadband excitation and transfer paths (GearTwin.Gearbox21Measured binds them; zero here and
  // folded away by the build).
  Real excitation_mesh_displacement(unit = "m") = 0 "Transmission error of the flank roughness, added to the approach of the flanks";
  Real excitation_mesh_displacement_rate(unit = "m/s") = 0 "Time derivative of excitation_mesh_displacement";
  Real excitation_off_line_force(unit = "N") = 0 "Process force on the pinion across the line of action (like effect_off_line_force)";
  Real sensor_path_acceleration_pinion(unit = "m/s2") = 0 "What the transfer path and sensor add to the pinion-side casing acceleration";
  Real sensor_path_acceleration_gear(unit = "m/s2") = 0 "What the transfer path and sensor add to the gear-side casing acceleration";
  // Motion of the casing under the bearing pedestals (GearTwin.Gearbox21Casing binds them; zero
  // here: the pedestals stand on rigid ground, as in the paper). Both pedestals of a shaft sit at
  // the same point of the gear plane.
  Real support_input_x(unit = "m") = 0 "Horizontal displacement of the casing under pedestals 4 and 6";
  Real support_input_y(unit = "m") = 0 "Vertical displacement of the casing under pedestals 4 and 6";
  Real support_output_x(unit = "m") = 0 "Horizontal displacement of the casing under pedestals 9 and 11";
  Real support_output_y(unit = "m") = 0 "Vertical displacement of the casing under pedestals 9 and 11";
  Real support_input_vx(unit = "m/s") = 0 "Time derivative of support_input_x";
  Real support_input_vy(unit = "m/s") = 0 "Time derivative of support_input_y";
  Real support_output_vx(unit = "m/s") = 0 "Time derivative of support_output_x";
  Real support_output_vy(unit = "m/s") = 0 "Time derivative of support_output_y";
  // Forces of a shaft modelled as a beam with the parts it carries outside its bearings
  // (overhung couplings, slip rings and encoders: GearTwin.Gearbox21Overhangs binds them; zero
  // here, as in the paper, whose model keeps only their rotation), on the gear bodies and on the
  // pedestals.
  Real shaft_force_x4(unit = "N") = 0 "Horizontal force of the input shaft on pedestal 4, beyond kx45";
  Real shaft_force_y4(unit = "N") = 0 "Vertical force of the input shaft on pedestal 4, beyond ky45";
  Real shaft_force_x6(unit = "N") = 0 "Horizontal force of the input shaft on pedestal 6, beyond kx56";
  Real shaft_force_y6(unit = "N") = 0 "Vertical force of the input shaft on pedestal 6, beyond ky56";
  Real shaft_force_x9(unit = "N") = 0 "Horizontal force of the output shaft on pedestal 9, beyond kx910";
  Real shaft_force_y9(unit = "N") = 0 "Vertical force of the output shaft on pedestal 9, beyond ky910";
  Real shaft_force_x11(unit = "N") = 0 "Horizontal force of the output shaft on pedestal 11, beyond kx1011";
  Real shaft_force_y11(unit = "N") = 0 "Vertical force of the output shaft on pedestal 11, beyond ky1011";
  Real shaft_force_x5(unit = "N") = 0 "Horizontal force of its shaft on the pinion, beyond the shaft springs";
  Real shaft_force_x10(unit = "N") = 0 "Horizontal force of its shaft on the gear, beyond the shaft springs";
  Real shaft_force_y5(unit = "N") = 0 "Vertical force of its shaft on the pinion, beyond the shaft springs";
  Real shaft_force_y10(unit = "N") = 0 "Vertical force of its shaft on the gear, beyond the shaft springs";
equation
  // Tooth-pair bookkeeping without events: the mesh phase is wrapped with atan2; the angle of
  // the last entered tooth counts the completed mesh cycles k, which name the teeth in contact.
  mesh_angle = z1 * theta5 + mesh_phase0;
  cycle_fraction = atan2(sin(mesh_angle - GearTwin.pi), cos(mesh_angle - GearTwin.pi)) / (2 * GearTwin.pi) + 0.5;
  tooth_angle = (mesh_angle - 2 * GearTwin.pi * cycle_fraction) / z1;
  roll = {(cycle_fraction + 1) / contact_ratio, cycle_fraction / contact_ratio, (cycle_fraction - 1) / contact_ratio};
  // Either gear moved bodily along the line of action by u (run-out: effect_mesh_displacement)
  // moves its base circle along that line: the pinion's flank crosses the line where it did (the
  // pair's roll, k_pair and the pinion's profile deviation stay), but the gear's tip reaches the
  // line u sooner, so contact starts u earlier along the path; the pinion's tip, which ends it,
  // stays at its roll. Elastic approach is local deformation, not a rigid move: it does not count.
  // A move w normal to the line (positive toward the other gear's side of it, where it shortens
  // the centre distance a by w cos(alpha)) moves the gear's tip circle too: the path of contact
  // starts where a sin(alpha') - sqrt(ra2^2 - rb2^2) from the pinion's base tangent, and
  // d(a sin(alpha'))/da = 1/sin(alpha'), so contact starts w / tan(alpha) earlier (ISO 21771
  // centre-distance geometry, to first order in w); run-out moves both, once per revolution.
  window = {noEvent(min(1.0, max(0.0, (roll[i] + (effect_mesh_displacement + effect_off_line_displacement / tan(alpha)) / contact_path_length + contact_smoothing) / (2 * contact_smoothing)))) ^ 2 * (3 - 2 * noEvent(min(1.0, max(0.0, (roll[i] + (effect_mesh_displacement + effect_off_line_displacement / tan(alpha)) / contact_path_length + contact_smoothing) / (2 * contact_smoothing))))) * noEvent(min(1.0, max(0.0, (1 - roll[i] + contact_smoothing) / (2 * contact_smoothing)))) ^ 2 * (3 - 2 * noEvent(min(1.0, max(0.0, (1 - roll[i] + contact_smoothing) / (2 * contact_smoothing))))) for i in 1:3};
  // Each pair reads the entries of the tooth it holds (array indices computed without events:
  // a lookup, whatever z1 and n_profile), the leading pair the tooth ahead, the next pair the
  // tooth behind.
  pair_tooth = {noEvent(mod(integer(tooth_angle * z1 / (2 * GearTwin.pi) + 0.5) + i - 2, z1)) + 1 for i in 1:3};
  profile_position = {noEvent(min(1.0, max(0.0, roll[i]))) * (n_profile - 1) for i in 1:3};
  pair_node = {noEvent(min(integer(profile_position[i]), n_profile - 2)) for i in 1:3};
  pair_tooth_factor = {tooth_stiffness_factor[noEvent(integer(pair_tooth[i]))] * effect_tooth_stiffness_factor[noEvent(integer(pair_tooth[i]))] for i in 1:3};
  pair_tooth_offset = {tooth_deviation_offset[noEvent(integer(pair_tooth[i]))] + effect_tooth_offset[noEvent(integer(pair_tooth[i]))] for i in 1:3};
  // The pit field of that tooth at the contact point: linear between the two profile nodes
  // around it (the same hat functions as below, restricted to the two that are not zero).
  pair_pit_field = {tooth_pit_field[noEvent(integer((pair_tooth[i] - 1) * n_profile + pair_node[i])) + 1] * noEvent(max(0.0, 1 - abs(profile_position[i] - pair_node[i]))) + tooth_pit_field[noEvent(integer((pair_tooth[i] - 1) * n_profile + pair_node[i])) + 2] * noEvent(max(0.0, 1 - abs(profile_position[i] - (pair_node[i] + 1)))) for i in 1:3};
  // Piecewise-linear interpolation along the profile: hat functions on n_profile nodes.
  pair_stiffness = {mesh_stiffness_scale * window[i] * pair_tooth_factor[i] * sum(k_pair[n] * noEvent(max(0.0, 1 - abs(noEvent(min(1.0, max(0.0, roll[i]))) * (n_profile - 1) - (n - 1)))) for n in 1:n_profile) for i in 1:3};
  pair_deviation = {pair_tooth_offset[i] + effect_pair_deviation[i] + pair_pit_field[i] + sum((profile_deviation[n] + effect_profile_deviation[n]) * noEvent(max(0.0, 1 - abs(noEvent(min(1.0, max(0.0, roll[i]))) * (n_profile - 1) - (n - 1)))) for n in 1:n_profile) for i in 1:3};
  mesh_deflection = rb1 * theta5 - rb2 * theta10 + (x5 - x10) * sin(alpha) + (y5 - y10) * cos(alpha) + effect_mesh_displacement + excitation_mesh_displacement;
  mesh_deflection_rate = rb1 * omega5 - rb2 * omega10 + (vx5 - vx10) * sin(alpha) + (vy5 - vy10) * cos(alpha) + effect_mesh_displacement_rate + excitation_mesh_displacement_rate;
  // A pair whose flanks are apart (deviation larger than the approach) carries no load.
  // Across the face the flanks touch first at one end when their leads differ by face_mismatch
  // (D): with a uniform stiffness per unit face width and an approach a at that end, the pair
  // carries k (a - D/2) while the whole face touches (a >= D) and k a^2 / (2 D) while only the
  // length a/D of it does; with D = 0 it is the line contact k max(0, a).
  face_mismatch = abs(lead_mismatch + effect_lead_mismatch);
  pair_force = {pair_stiffness[i] * noEvent(if face_mismatch > 0 then min(max(mesh_deflection - pair_deviation[i], 0.0), face_mismatch) ^ 2 / (2 * max(face_mismatch, 1e-12)) + max(mesh_deflection - pair_deviation[i] - face_mismatch, 0.0) else max(0.0, mesh_deflection - pair_deviation[i])) for i in 1:3};
  // The flanks damp each other only while they touch (oil film, material damping); apart, the
  // gears fly freely across the clearance.
  mesh_contact = noEvent(min(1.0, sum(window[i] * noEvent(min(1.0, max(0.0, (mesh_deflection - pair_deviation[i]) / contact_damping_width))) for i in 1:3)));
  mesh_force = pair_force[1] + pair_force[2] + pair_force[3] + mesh_contact * c_mesh * mesh_deflection_rate + effect_mesh_force;
  mesh_stiffness = pair_stiffness[1] + pair_stiffness[2] + pair_stiffness[3];
  transmission_error = rb1 * theta5 - rb2 * theta10;
  motor_torque = drive_torque + c_motor * (motor_speed_ref - omega1) + effect_drive_torque;

  // ---- Torsional equations ------------------------------------------------------------------
  der(theta1) = omega1;
  der(theta2) = omega2;
  der(theta3) = omega3;
  der(theta5) = omega5;
  der(theta7) = omega7;
  der(theta8) = omega8;
  der(theta10) = omega10;
  der(theta12) = omega12;
  der(theta13) = omega13;
  I1 * der(omega1) = motor_torque - kt12 * (theta1 - theta2) - ct12 * (omega1 - omega2);
  I2 * der(omega2) = kt12 * (theta1 - theta2) + ct12 * (omega1 - omega2) - kt23 * (theta2 - theta3) - ct23 * (omega2 - omega3);
  I3 * der(omega3) = kt23 * (theta2 - theta3) + ct23 * (omega2 - omega3) - kt35 * (theta3 - theta5) - ct35 * (omega3 - omega5);
  I5 * der(omega5) = kt35 * (theta3 - theta5) + ct35 * (omega3 - omega5) - kt57 * (theta5 - theta7) - ct57 * (omega5 - omega7) - rb1 * mesh_force + effect_pinion_torque;
  I7 * der(omega7) = kt57 * (theta5 - theta7) + ct57 * (omega5 - omega7);
  I8 * der(omega8) = kt810 * (theta10 - theta8) + ct810 * (omega10 - omega8);
  I10 * der(omega10) = rb2 * mesh_force + effect_gear_torque - kt810 * (theta10 - theta8) - ct810 * (omega10 - omega8) - kt1012 * (theta10 - theta12) - ct1012 * (omega10 - omega12);
  I12 * der(omega12) = kt1012 * (theta10 - theta12) + ct1012 * (omega10 - omega12) - kt1213 * (theta12 - theta13) - ct1213 * (omega12 - omega13);
  I13 * der(omega13) = kt1213 * (theta12 - theta13) + ct1213 * (omega12 - omega13) - load_torque - effect_load_torque;

  // ---- Lateral equations --------------------------------------------------------------------
  der(x4) = vx4;
  der(y4) = vy4;
  der(x5) = vx5;
  der(y5) = vy5;
  der(x6) = vx6;
  der(y6) = vy6;
  der(x9) = vx9;
  der(y9) = vy9;
  der(x10) = vx10;
  der(y10) = vy10;
  der(x11) = vx11;
  der(y11) = vy11;
  m4 * der(vx4) = -kx4 * (x4 - support_input_x) - cx4 * (vx4 - support_input_vx) + kx45 * (x5 - x4) + cx45 * (vx5 - vx4) + shaft_force_x4;
  m4 * der(vy4) = -ky4 * (y4 - support_input_y) - cy4 * (vy4 - support_input_vy) + ky45 * (y5 - y4) + cy45 * (vy5 - vy4) + shaft_force_y4;
  m5 * der(vx5) = -kx45 * (x5 - x4) - cx45 * (vx5 - vx4) - kx56 * (x5 - x6) - cx56 * (vx5 - vx6) - mesh_force * sin(alpha) + (effect_off_line_force + excitation_off_line_force) * cos(alpha) + shaft_force_x5;
  m5 * der(vy5) = -ky45 * (y5 - y4) - cy45 * (vy5 - vy4) - ky56 * (y5 - y6) - cy56 * (vy5 - vy6) - mesh_force * cos(alpha) - (effect_off_line_force + excitation_off_line_force) * sin(alpha) + shaft_force_y5;
  m6 * der(vx6) = -kx6 * (x6 - support_input_x) - cx6 * (vx6 - support_input_vx) + kx56 * (x5 - x6) + cx56 * (vx5 - vx6) + shaft_force_x6;
  m6 * der(vy6) = -ky6 * (y6 - support_input_y) - cy6 * (vy6 - support_input_vy) + ky56 * (y5 - y6) + cy56 * (vy5 - vy6) + shaft_force_y6;
  m9 * der(vx9) = -kx9 * (x9 - support_output_x) - cx9 * (vx9 - support_output_vx) + kx910 * (x10 - x9) + cx910 * (vx10 - vx9) + shaft_force_x9;
  m9 * der(vy9) = -ky9 * (y9 - support_output_y) - cy9 * (vy9 - support_output_vy) + ky910 * (y10 - y9) + cy910 * (vy10 - vy9) + shaft_force_y9;
  m10 * der(vx10) = -kx910 * (x10 - x9) - cx910 * (vx10 - vx9) - kx1011 * (x10 - x11) - cx1011 * (vx10 - vx11) + mesh_force * sin(alpha) - (effect_off_line_force + excitation_off_line_force) * cos(alpha) + shaft_force_x10;
  m10 * der(vy10) = -ky910 * (y10 - y9) - cy910 * (vy10 - vy9) - ky1011 * (y10 - y11) - cy1011 * (vy10 - vy11) + mesh_force * cos(alpha) + (effect_off_line_force + excitation_off_line_force) * sin(alpha) + shaft_force_y10;
  m11 * der(vx11) = -kx11 * (x11 - support_output_x) - cx11 * (vx11 - support_output_vx) + kx1011 * (x10 - x11) + cx1011 * (vx10 - vx11) + shaft_force_x11;
  m11 * der(vy11) = -ky11 * (y11 - support_output_y) - cy11 * (vy11 - support_output_vy) + ky1011 * (y10 - y11) + cy1011 * (vy10 - vy11) + shaft_force_y11;

  // ---- Sensors ------------------------------------------------------------------------------
  casing_acceleration_pinion = cos(sensor_angle_pinion) * der(vy6) + sin(sensor_angle_pinion) * der(vx6);
  accel_pinion_casing = casing_acceleration_pinion + effect_sensor_acceleration_pinion + sensor_path_acceleration_pinion;
  accel_gear_casing = cos(sensor_angle_gear) * der(vy9) + sin(sensor_angle_gear) * der(vx9) + sensor_path_acceleration_gear;
  annotation(experiment(StartTime = 0, StopTime = 1, Interval = 1e-4));
end Gearbox21;
