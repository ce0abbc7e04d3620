within GearTwin;
model Gearbox21Measured "GearTwin.Gearbox21 as its casing accelerometers measure it: flank roughness and a process force (broadband, seeded) and the transfer path to each sensor"
  extends GearTwin.Gearbox21(
    excitation_mesh_displacement = pinion_roughness.displacement + gear_roughness.displacement,
    excitation_mesh_displacement_rate = pinion_roughness.displacement_rate + gear_roughness.displacement_rate,
    excitation_off_line_force = process.force,
    sensor_path_acceleration_pinion = sensor_pinion.acceleration - sensor_pinion.near_acceleration,
    sensor_path_acceleration_gear = sensor_gear.acceleration - sensor_gear.near_acceleration);
  parameter Boolean broadband = true "Switch: false removes the roughness and the process force (the build folds them away)";
  GearTwin.Excitation.RoughnessTransmissionError pinion_roughness(enabled = broadband, seed = 1, angle = theta5, speed = omega5, rolling_radius = pitch_curvature_pinion, contact_half_width = hertz_half_width) "Roughness of the pinion flanks (orders of the input shaft up to the Hertzian width)";
  GearTwin.Excitation.RoughnessTransmissionError gear_roughness(enabled = broadband, seed = 2, angle = theta10, speed = omega10, rolling_radius = pitch_curvature_gear, contact_half_width = hertz_half_width) "Roughness of the gear flanks (orders of the output shaft up to the Hertzian width)";
  GearTwin.Excitation.ProcessForce process(enabled = broadband, seed = 3) "Friction and lubricant-film forces at the mesh, across the line of action";
  GearTwin.Sensors.CasingAccelerometer sensor_pinion(near_acceleration = cos(sensor_angle_pinion) * der(vy6) + sin(sensor_angle_pinion) * der(vx6), far_acceleration = cos(sensor_angle_pinion) * der(vy4) + sin(sensor_angle_pinion) * der(vx4)) "B&K 4396 on the input-shaft casing (near: pedestal 6)";
  GearTwin.Sensors.CasingAccelerometer sensor_gear(near_acceleration = cos(sensor_angle_gear) * der(vy9) + sin(sensor_angle_gear) * der(vx9), far_acceleration = cos(sensor_angle_gear) * der(vy11) + sin(sensor_angle_gear) * der(vx11)) "B&K 4394 on the output-shaft casing (near: pedestal 9)";
end Gearbox21Measured;
