within GearTwin;
model Gearbox21Casing "GearTwin.Gearbox21Measured with the casing in the loop: the pedestals stand on a rigid casing that moves in the gear plane on its mounts, and the accelerometers sit on the casing"
  // The paper's model stands the four bearing pedestals on rigid ground and reads the sensors on
  // the pedestals. Here the pedestals' supports are points of a casing, rigid in the gear plane
  // (x, y, rotation phi about its centre of mass), bolted to the ground by two mounts below it.
  // The pedestals push the casing and the casing moves them back (two-way), so the casing adds
  // its own modes on the mounts, and a horizontal bearing force, acting above the centre of mass,
  // rocks the casing and reaches a vertical accelerometer that sits beside that centre.
  // A point (px, py) of the casing (relative to its centre of mass) moves by
  // (x_casing - py * phi_casing, y_casing + px * phi_casing) for small rotations. The pinion shaft
  // sits at (-centre_distance/2, shaft_height), the gear shaft at (+centre_distance/2, shaft_height);
  // the mounts at (-mount_spacing/2, -mount_height) and (+mount_spacing/2, -mount_height).
  extends GearTwin.Gearbox21(
    excitation_mesh_displacement = pinion_roughness.displacement + gear_roughness.displacement,
    excitation_mesh_displacement_rate = pinion_roughness.displacement_rate + gear_roughness.displacement_rate,
    excitation_off_line_force = process.force,
    sensor_path_acceleration_pinion = noEvent(if n_path_sections > 0 then sensor_pinion.gain * path_pinion.acceleration else sensor_pinion.acceleration) - casing_acceleration_pinion,
    sensor_path_acceleration_gear = noEvent(if n_path_sections > 0 then sensor_gear.gain * path_gear.acceleration else sensor_gear.acceleration) - (cos(sensor_angle_gear) * der(vy9) + sin(sensor_angle_gear) * der(vx9)),
    support_input_x = x_casing - shaft_height * phi_casing,
    support_input_y = y_casing - 0.5 * centre_distance * phi_casing,
    support_output_x = x_casing - shaft_height * phi_casing,
    support_output_y = y_casing + 0.5 * centre_distance * phi_casing,
    support_input_vx = vx_casing - shaft_height * w_casing,
    support_input_vy = vy_casing - 0.5 * centre_distance * w_casing,
    support_output_vx = vx_casing - shaft_height * w_casing,
    support_output_vy = vy_casing + 0.5 * centre_distance * w_casing);
  // ---- Casing and mounts (stated assumptions: a cast box about 0.30 x 0.25 m in the gear plane
  // with 8 mm walls and the bearing housings, bolted to a steel bedplate) ------------------------
  parameter Real m_casing(unit = "kg", min = 0) = 25.0 "Casing with the bearing housings, rigid in the gear plane";
  parameter Real I_casing(unit = "kg.m2", min = 0) = 0.33 "Casing inertia about its centre of mass, about the shaft axis direction";
  parameter Real kx_mount(unit = "N/m", min = 0) = 5.0e7 "Casing mount to ground (bolted foot on the bedplate), horizontal, each of two";
  parameter Real ky_mount(unit = "N/m", min = 0) = 1.0e8 "Casing mount to ground (bolted foot on the bedplate), vertical, each of two";
  parameter Real cx_mount(unit = "N.s/m", min = 0) = 2.0e3 "Casing mount damping, horizontal, each of two";
  parameter Real cy_mount(unit = "N.s/m", min = 0) = 2.0e3 "Casing mount damping, vertical, each of two";
  parameter Real centre_distance(unit = "m", min = 0) = 0.5 * module * (z1 + z2) "Distance between the shaft centres (standard centre distance)";
  parameter Real shaft_height(unit = "m") = 0.05 "Height of the shaft centres above the casing's centre of mass";
  parameter Real mount_spacing(unit = "m", min = 0) = 0.30 "Horizontal distance between the two mounts";
  parameter Real mount_height(unit = "m") = 0.10 "Height of the casing's centre of mass above the mounts";
  // ---- Broadband excitation and sensors (as GearTwin.Gearbox21Measured) -----------------------
  parameter Boolean broadband = true "Switch: false removes the roughness and the process force (the build folds them away)";
  GearTwin.Excitation.RoughnessTransmissionError pinion_roughness(enabled = broadband, seed = 1, angle = theta5, speed = omega5, rolling_radius = pitch_curvature_pinion, contact_half_width = hertz_half_width) "Roughness of the pinion flanks (orders of the input shaft up to the Hertzian width)";
  GearTwin.Excitation.RoughnessTransmissionError gear_roughness(enabled = broadband, seed = 2, angle = theta10, speed = omega10, rolling_radius = pitch_curvature_gear, contact_half_width = hertz_half_width) "Roughness of the gear flanks (orders of the output shaft up to the Hertzian width)";
  GearTwin.Excitation.ProcessForce process(enabled = broadband, seed = 3) "Friction and lubricant-film forces at the mesh, across the line of action";
  GearTwin.Sensors.CasingAccelerometer sensor_pinion(near_acceleration = cos(sensor_angle_pinion) * (der(vy_casing) - 0.5 * centre_distance * der(w_casing)) + sin(sensor_angle_pinion) * (der(vx_casing) - shaft_height * der(w_casing)), far_acceleration = cos(sensor_angle_pinion) * (der(vy_casing) - 0.5 * centre_distance * der(w_casing)) + sin(sensor_angle_pinion) * (der(vx_casing) - shaft_height * der(w_casing))) "B&K 4396 on the casing at the input-shaft bearing housing";
  GearTwin.Sensors.CasingAccelerometer sensor_gear(near_acceleration = cos(sensor_angle_gear) * (der(vy_casing) + 0.5 * centre_distance * der(w_casing)) + sin(sensor_angle_gear) * (der(vx_casing) - shaft_height * der(w_casing)), far_acceleration = cos(sensor_angle_gear) * (der(vy_casing) + 0.5 * centre_distance * der(w_casing)) + sin(sensor_angle_gear) * (der(vx_casing) - shaft_height * der(w_casing))) "B&K 4394 on the casing at the output-shaft bearing housing";
  // ---- Transfer path measured by hammer tests (structural: 0 sections keeps the modelled casing) --
  // With n_path_sections > 0 the sensors read the bearing forces through the accelerances measured
  // by striking the housings of the real gearbox (GearTwin.Sensors.MeasuredPath, fitted by `twin
  // calibrate` from hammer records); the casing above then only carries the pedestals.
  parameter Integer n_path_sections = 0 "Second-order sections of each sensor's measured transfer path (structural; 0: the modelled casing and sensor path)";
  GearTwin.Sensors.MeasuredPath path_pinion(n_sections = n_path_sections, n_forces = 4, force = {bearing_force_input_x, bearing_force_input_y, bearing_force_output_x, bearing_force_output_y}) "Measured path from the bearing forces to the B&K 4396";
  GearTwin.Sensors.MeasuredPath path_gear(n_sections = n_path_sections, n_forces = 4, force = {bearing_force_input_x, bearing_force_input_y, bearing_force_output_x, bearing_force_output_y}) "Measured path from the bearing forces to the B&K 4394";
  // ---- Casing states -----------------------------------------------------------------------------
  Real x_casing(unit = "m", start = 0.0, fixed = true, nominal = 1e-6) "Horizontal displacement of the casing's centre of mass";
  Real y_casing(unit = "m", start = 0.0, fixed = true, nominal = 1e-6) "Vertical displacement of the casing's centre of mass";
  Real phi_casing(unit = "rad", start = 0.0, fixed = true, nominal = 1e-5) "Rotation of the casing in the gear plane";
  Real vx_casing(unit = "m/s", start = 0.0, fixed = true, nominal = 1e-3) "Horizontal velocity of the casing's centre of mass";
  Real vy_casing(unit = "m/s", start = 0.0, fixed = true, nominal = 1e-3) "Vertical velocity of the casing's centre of mass";
  Real w_casing(unit = "rad/s", start = 0.0, fixed = true, nominal = 1e-2) "Angular velocity of the casing in the gear plane";
  Real pedestal_force_input_x(unit = "N") "Force of pedestals 4 and 6 on the casing, horizontal";
  Real pedestal_force_input_y(unit = "N") "Force of pedestals 4 and 6 on the casing, vertical";
  Real pedestal_force_output_x(unit = "N") "Force of pedestals 9 and 11 on the casing, horizontal";
  Real pedestal_force_output_y(unit = "N") "Force of pedestals 9 and 11 on the casing, vertical";
  Real mount_force_x[2](each unit = "N") "Force of each mount on the casing, horizontal";
  Real mount_force_y[2](each unit = "N") "Force of each mount on the casing, vertical";
  // The force the shafts put into their housings through the bearings (each housing's inertia force
  // plus what it passes on to the casing). With the housings held still (their masses made very
  // large) these are the blocked forces, which a transfer path measured by striking the housings
  // of the assembled gearbox turns into the casing response (ISO 20270).
  output Real bearing_force_input_x(unit = "N") "Force of the input shaft through its bearings on housings 4 and 6, horizontal";
  output Real bearing_force_input_y(unit = "N") "Force of the input shaft through its bearings on housings 4 and 6, vertical";
  output Real bearing_force_output_x(unit = "N") "Force of the output shaft through its bearings on housings 9 and 11, horizontal";
  output Real bearing_force_output_y(unit = "N") "Force of the output shaft through its bearings on housings 9 and 11, vertical";
equation
  pedestal_force_input_x = kx4 * (x4 - support_input_x) + cx4 * (vx4 - support_input_vx) + kx6 * (x6 - support_input_x) + cx6 * (vx6 - support_input_vx);
  pedestal_force_input_y = ky4 * (y4 - support_input_y) + cy4 * (vy4 - support_input_vy) + ky6 * (y6 - support_input_y) + cy6 * (vy6 - support_input_vy);
  pedestal_force_output_x = kx9 * (x9 - support_output_x) + cx9 * (vx9 - support_output_vx) + kx11 * (x11 - support_output_x) + cx11 * (vx11 - support_output_vx);
  pedestal_force_output_y = ky9 * (y9 - support_output_y) + cy9 * (vy9 - support_output_vy) + ky11 * (y11 - support_output_y) + cy11 * (vy11 - support_output_vy);
  bearing_force_input_x = m4 * der(vx4) + m6 * der(vx6) + pedestal_force_input_x;
  bearing_force_input_y = m4 * der(vy4) + m6 * der(vy6) + pedestal_force_input_y;
  bearing_force_output_x = m9 * der(vx9) + m11 * der(vx11) + pedestal_force_output_x;
  bearing_force_output_y = m9 * der(vy9) + m11 * der(vy11) + pedestal_force_output_y;
  // mount j at (s_j * mount_spacing / 2, -mount_height), s = {-1, +1}
  mount_force_x = {-kx_mount * (x_casing + mount_height * phi_casing) - cx_mount * (vx_casing + mount_height * w_casing) for j in 1:2};
  mount_force_y = {-ky_mount * (y_casing + (2 * j - 3) * 0.5 * mount_spacing * phi_casing) - cy_mount * (vy_casing + (2 * j - 3) * 0.5 * mount_spacing * w_casing) for j in 1:2};
  der(x_casing) = vx_casing;
  der(y_casing) = vy_casing;
  der(phi_casing) = w_casing;
  m_casing * der(vx_casing) = pedestal_force_input_x + pedestal_force_output_x + mount_force_x[1] + mount_force_x[2];
  m_casing * der(vy_casing) = pedestal_force_input_y + pedestal_force_output_y + mount_force_y[1] + mount_force_y[2];
  // moment px * Fy - py * Fx of each force about the centre of mass
  I_casing * der(w_casing) = -0.5 * centre_distance * pedestal_force_input_y - shaft_height * pedestal_force_input_x + 0.5 * centre_distance * pedestal_force_output_y - shaft_height * pedestal_force_output_x + sum((2 * j - 3) * 0.5 * mount_spacing * mount_force_y[j] + mount_height * mount_force_x[j] for j in 1:2);
end Gearbox21Casing;
