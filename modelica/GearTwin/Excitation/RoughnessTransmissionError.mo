within GearTwin.Excitation;
block RoughnessTransmissionError "Transmission error of the flank roughness of one gear: random-phase orders of its shaft, seen through the Hertzian contact"
  // Roughness is geometry on the flanks, so its transmission error repeats with every revolution
  // of the gear that carries it: a sum of shaft orders with random phases. A wavelength lambda on
  // a flank of rolling radius rho is shaft order n = 2 pi rho / lambda. The contact averages the
  // profile over its Hertzian width 2 b, so order n reaches the mesh with the factor
  // exp(-(n b / rho)^2 / 8) (the Gaussian fit of the elliptic pressure's transform 2 J1(k b)/(k b),
  // k = n / rho): the band ends where the wavelength nears the contact width, not at a fixed order,
  // and a gear with a larger rolling radius carries its roughness to proportionally higher orders.
  // Amplitudes fall as n^-slope above the corner order 32 and stay flat below it (waviness of
  // longer wavelength is the manufacturing deviations' part, modelled apart).
  // Built as a product of three short sums (GearTwin.Excitation.Harmonics),
  //   TE = rms/norm * (P * Q * R - p_0/8),
  //   P = p_0/2 + sum_{j=1..32} p_j cos(63 j a + phi_j),  Q = 1/2 + sum_{k=1..4} cos(7 k a + psi_k),
  //   R = 1/2 + sum_{l=1..3} cos(l a + chi_l),
  // whose terms land at 63 j +- 7 k +- l: every order from 1 to 2047 exactly once, each with
  // amplitude p_j/4 (the block j = 0 holds orders 1..31; p_0/8 is the product's mean).
  // Phases come from the seed by a fixed hash (the sine of a large multiple): the same seed gives
  // the same roughness everywhere.
  parameter Boolean enabled = true "false: no roughness; the build folds the block away (structural)";
  parameter Real rms(unit = "m", min = 0, max = 1e-5) = 5e-8 "RMS transmission error of the roughness";
  parameter Real slope(min = 0, max = 3) = 1 "Amplitude of order n falls as n^-slope above order 32";
  parameter Real rolling_radius(unit = "m", min = 0) = 0.01 "Radius of curvature of the flank at the pitch point (r sin(alpha)), which turns a wavelength into an order";
  parameter Real contact_half_width(unit = "m", min = 0) = 0 "Hertzian half-width of the contact over which the profile is averaged (0: no averaging)";
  parameter Real seed = 1 "Another seed draws other phases";
  input Real angle(unit = "rad") "Angle of the gear that carries the roughness";
  input Real speed(unit = "rad/s") "Its speed";
  output Real displacement(unit = "m") "Transmission error along the line of action (added to the approach)";
  output Real displacement_rate(unit = "m/s") "Its time derivative";
  parameter Real p0 = 32 ^ (-slope) * exp(-(16 * contact_half_width / rolling_radius) ^ 2 / 8) "Amplitude of the block of orders 1..31";
  parameter Real p[32] = {(63 * j) ^ (-slope) * exp(-(63 * j * contact_half_width / rolling_radius) ^ 2 / 8) for j in 1:32} "Amplitude of the block of orders 63 j - 31 .. 63 j + 31";
  parameter Real phi[32](each unit = "rad") = {43758.5453 * sin(12.9898 * j + 78.233 * seed) for j in 1:32};
  parameter Real psi[4](each unit = "rad") = {43758.5453 * sin(39.3468 * k + 11.135 * seed) for k in 1:4};
  parameter Real chi[3](each unit = "rad") = {43758.5453 * sin(93.9898 * l + 67.345 * seed) for l in 1:3};
  parameter Real norm = sqrt((31 * p0 ^ 2 + 63 * sum(p[j] ^ 2 for j in 1:32)) / 32) "RMS of P * Q * R - p0/8";
  GearTwin.Excitation.Harmonics fine(x = angle) "Orders 1..32 of the shaft";
  GearTwin.Excitation.Harmonics middle(x = 7 * angle) "Orders 7, 14, .. 224";
  GearTwin.Excitation.Harmonics coarse(x = 63 * angle) "Orders 63, 126, .. 2016";
  Real P = p0 / 2 + sum(p[j] * (coarse.c[j] * cos(phi[j]) - coarse.s[j] * sin(phi[j])) for j in 1:32);
  Real dP = -sum(63 * j * p[j] * (coarse.s[j] * cos(phi[j]) + coarse.c[j] * sin(phi[j])) for j in 1:32) "dP/d(angle)";
  Real Q = 1 / 2 + sum(middle.c[k] * cos(psi[k]) - middle.s[k] * sin(psi[k]) for k in 1:4);
  Real dQ = -sum(7 * k * (middle.s[k] * cos(psi[k]) + middle.c[k] * sin(psi[k])) for k in 1:4) "dQ/d(angle)";
  Real R = 1 / 2 + sum(fine.c[l] * cos(chi[l]) - fine.s[l] * sin(chi[l]) for l in 1:3);
  Real dR = -sum(l * (fine.s[l] * cos(chi[l]) + fine.c[l] * sin(chi[l])) for l in 1:3) "dR/d(angle)";
equation
  displacement = noEvent(if enabled then rms / norm * (P * Q * R - p0 / 8) else 0);
  displacement_rate = noEvent(if enabled then rms / norm * speed * (dP * Q * R + P * dQ * R + P * Q * dR) else 0);
end RoughnessTransmissionError;
