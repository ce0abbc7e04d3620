within GearTwin.Excitation;
block RoughnessTransmissionError "Transmission error of the flank roughness of one gear: random-phase orders of its shaft"
  // Roughness is geometry on the flanks, so its transmission error repeats with every revolution
  // of the gear that carries it: a sum of shaft orders with random phases, amplitudes falling
  // with the order as n^-slope. It is built as a product of two short sums,
  //   TE = rms/norm * P * Q,  P = sum_j p_j cos(j K a + phi_j),  Q = 1/sqrt(2) + sum_k cos(k a + psi_k),
  // j = 1..16, k = 1..8, K = 16: the product holds every order from 8 to 264 once (j K +- k), at
  // the cost of two short sums (GearTwin.Excitation.Harmonics). Phases come from the seed by a
  // fixed hash (the sine of a large multiple): the same seed gives the same roughness everywhere.
  parameter Boolean enabled = true "false: no roughness; the build folds the block away (structural)";
  parameter Real rms(unit = "m", min = 0, max = 1e-5) = 5e-8 "RMS transmission error of the roughness";
  parameter Real slope(min = 0, max = 3) = 1 "Amplitude of order n falls as n^-slope";
  parameter Real seed = 1 "Another seed draws other phases";
  input Real angle(unit = "rad") "Angle of the gear that carries the roughness";
  input Real speed(unit = "rad/s") "Its speed";
  output Real displacement(unit = "m") "Transmission error along the line of action (added to the approach)";
  output Real displacement_rate(unit = "m/s") "Its time derivative";
  parameter Real p[16] = {(16 * j) ^ (-slope) for j in 1:16} "Amplitude of each block of orders";
  parameter Real phi[16](each unit = "rad") = {43758.5453 * sin(12.9898 * j + 78.233 * seed) for j in 1:16};
  parameter Real psi[8](each unit = "rad") = {43758.5453 * sin(39.3468 * k + 11.135 * seed) for k in 1:8};
  parameter Real norm = sqrt(sum(p[j] ^ 2 for j in 1:16) / 2 * (1 + 8) / 2) "RMS of P * Q";
  GearTwin.Excitation.Harmonics fine(x = angle) "Orders 1..32 of the shaft";
  GearTwin.Excitation.Harmonics coarse(x = 16 * angle) "Orders 16, 32, .. 512";
  Real P = sum(p[j] * (coarse.c[j] * cos(phi[j]) - coarse.s[j] * sin(phi[j])) for j in 1:16);
  Real dP = -sum(16 * j * p[j] * (coarse.s[j] * cos(phi[j]) + coarse.c[j] * sin(phi[j])) for j in 1:16) "dP/d(angle)";
  Real Q = 1 / sqrt(2) + sum(fine.c[k] * cos(psi[k]) - fine.s[k] * sin(psi[k]) for k in 1:8);
  Real dQ = -sum(k * (fine.s[k] * cos(psi[k]) + fine.c[k] * sin(psi[k])) for k in 1:8) "dQ/d(angle)";
equation
  displacement = noEvent(if enabled then rms / norm * P * Q else 0);
  displacement_rate = noEvent(if enabled then rms / norm * speed * (dP * Q + P * dQ) else 0);
end RoughnessTransmissionError;
