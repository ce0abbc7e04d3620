within GearTwin.Excitation;
block ProcessForce "Broadband force of the process, fixed in frequency: a dense random-phase multisine"
  // Forces that do not follow the shafts (sliding friction at the mesh through the lubricant
  // film, asperity contacts) make a continuous spectrum that stays put when the speed changes.
  // Built as a product of three short random-phase sums,
  //   F = rms/norm * P * Q * R,   P = 1/sqrt(2) + sum_{j=1..32} cos(j a + phi_j),   a = 2 pi fc t, fc = f_high/32,
  //   Q = 1/sqrt(2) + sum_{k=1..16} cos(k b + psi_k),   b = a / 33,
  //   R = 1/sqrt(2) + sum_{l=1..16} cos(l g + chi_l),   g = b / 33,
  // whose terms land at j fc +- k fc/33 +- l fc/1089 (j = 0 too): a flat spectrum up to f_high with lines
  // 0.3 Hz apart (f_high = 10 kHz), about 70 000 of them, for three short sums per evaluation
  // (GearTwin.Excitation.Harmonics). The product of independent sums is not Gaussian (its
  // envelope breathes over ~0.1 s) but its spectrum, which is what the structure filters, is
  // flat and dense. Phases come from the seed by a fixed hash.
  parameter Boolean enabled = true "false: no force; the build folds the block away (structural)";
  parameter Real rms(unit = "N", min = 0, max = 1e4) = 1 "RMS force";
  parameter Real f_high(unit = "Hz", min = 100) = 10000 "Upper edge of the band";
  parameter Real seed = 3 "Another seed draws other phases";
  parameter Real phi[32](each unit = "rad") = {43758.5453 * sin(12.9898 * j + 78.233 * seed) for j in 1:32};
  parameter Real psi[16](each unit = "rad") = {43758.5453 * sin(39.3468 * k + 11.135 * seed) for k in 1:16};
  parameter Real chi[16](each unit = "rad") = {43758.5453 * sin(93.9898 * l + 67.345 * seed) for l in 1:16};
  parameter Real norm = sqrt((1 + 32) / 2 * (1 + 16) / 2 * (1 + 16) / 2) "RMS of P * Q * R";
  GearTwin.Excitation.Harmonics carrier(x = 2 * GearTwin.pi * f_high / 32 * time);
  GearTwin.Excitation.Harmonics middle(x = 2 * GearTwin.pi * f_high / 32 / 33 * time);
  GearTwin.Excitation.Harmonics low(x = 2 * GearTwin.pi * f_high / 32 / 33 / 33 * time);
  Real P = 1 / sqrt(2) + sum(carrier.c[j] * cos(phi[j]) - carrier.s[j] * sin(phi[j]) for j in 1:32);
  Real Q = 1 / sqrt(2) + sum(middle.c[k] * cos(psi[k]) - middle.s[k] * sin(psi[k]) for k in 1:16);
  Real R = 1 / sqrt(2) + sum(low.c[l] * cos(chi[l]) - low.s[l] * sin(chi[l]) for l in 1:16);
  output Real force(unit = "N") "The force";
equation
  force = noEvent(if enabled then rms / norm * P * Q * R else 0);
end ProcessForce;
