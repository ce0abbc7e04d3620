within GearTwin.Sensors;
block MeasuredPath "Acceleration at a sensor from the forces the shafts put into their housings, through the transfer path measured by striking the housings (a rational fit of the measured accelerances)"
  // In-situ transfer path analysis (ISO 20270): the response at a sensor of an assembled machine is
  // the sum over its force inputs of the accelerance measured from that input to the sensor (a hammer
  // struck at the housing, the sensor recording) times the force the source puts in there. The
  // measured accelerances come here as one rational function per force with common poles, in
  // second-order sections (observer canonical form, two states per section whatever the number of
  // forces):
  //   H_k(s) = sum_r (c1[r,k] s + c0[r,k]) / (s^2 + 2 zeta_r omega_r s + omega_r^2) + d_k,
  //   der(x1_r) = -2 zeta_r omega_r x1_r + x2_r + sum_k c1[r,k] F_k,
  //   der(x2_r) = -omega_r^2 x1_r + sum_k c0[r,k] F_k,   a = sum_r x1_r + sum_k d_k F_k.
  // The coefficients come from `twin calibrate` (twin.transfer_path), not from any physics stated here:
  // what the casing, its walls and the sensor's mount do between a housing and the sensor is what the
  // hammer test measured. c1 and c0 are stored row by row, [(r - 1) * n_forces + k].
  parameter Integer n_sections = 0 "Second-order sections of the fit (structural; 0: no path)";
  parameter Integer n_forces = 4 "Force inputs (structural)";
  parameter Real section_frequency[n_sections](each unit = "Hz", each min = 1) = fill(1000, n_sections) "Undamped natural frequency of each section";
  parameter Real section_damping[n_sections](each min = 1e-4, each max = 2) = fill(0.05, n_sections) "Damping ratio of each section";
  parameter Real residue_rate[n_sections * n_forces](each unit = "1/kg") = zeros(n_sections * n_forces) "c1: numerator coefficient of s, per section and force";
  parameter Real residue[n_sections * n_forces](each unit = "rad/(kg.s)") = zeros(n_sections * n_forces) "c0: constant numerator coefficient, per section and force";
  parameter Real feedthrough[n_forces](each unit = "1/kg") = zeros(n_forces) "d: accelerance left at high frequency, per force";
  input Real force[n_forces](each unit = "N") "Forces of the shafts on the housings, in the order the fit was made for";
  output Real acceleration(unit = "m/s2") "Acceleration at the sensor";
  Real x1[n_sections](each unit = "m/s2", each start = 0) "First state of each section: its share of the acceleration";
  Real x2[n_sections](each unit = "m/s3", each start = 0) "Second state of each section";
equation
  der(x1) = {-2 * section_damping[r] * 2 * GearTwin.pi * section_frequency[r] * x1[r] + x2[r] + sum(residue_rate[(r - 1) * n_forces + k] * force[k] for k in 1:n_forces) for r in 1:n_sections};
  der(x2) = {-(2 * GearTwin.pi * section_frequency[r]) ^ 2 * x1[r] + sum(residue[(r - 1) * n_forces + k] * force[k] for k in 1:n_forces) for r in 1:n_sections};
  acceleration = sum(x1) + sum(feedthrough[k] * force[k] for k in 1:n_forces);
end MeasuredPath;
