within GearTwin.Excitation;
block Harmonics "cos(k x) and sin(k x) for k = 1..32, by repeated angle doubling: two sines for all of them"
  // Stage m holds k = 1..2^m: its second half is its first half turned by 2^(m-1) x
  // (angle addition), so 32 harmonics cost one sine, one cosine and 31 complex products.
  input Real x(unit = "rad") "Angle";
  output Real c[32] "cos(k x)";
  output Real s[32] "sin(k x)";
  Real c1 = cos(x);
  Real s1 = sin(x);
  Real c2[2] = {c1, c1 * c1 - s1 * s1};
  Real s2[2] = {s1, 2 * s1 * c1};
  Real c4[4] = {noEvent(if k <= 2 then c2[k] else c2[max(k - 2, 1)] * c2[2] - s2[max(k - 2, 1)] * s2[2]) for k in 1:4};
  Real s4[4] = {noEvent(if k <= 2 then s2[k] else s2[max(k - 2, 1)] * c2[2] + c2[max(k - 2, 1)] * s2[2]) for k in 1:4};
  Real c8[8] = {noEvent(if k <= 4 then c4[k] else c4[max(k - 4, 1)] * c4[4] - s4[max(k - 4, 1)] * s4[4]) for k in 1:8};
  Real s8[8] = {noEvent(if k <= 4 then s4[k] else s4[max(k - 4, 1)] * c4[4] + c4[max(k - 4, 1)] * s4[4]) for k in 1:8};
  Real c16[16] = {noEvent(if k <= 8 then c8[k] else c8[max(k - 8, 1)] * c8[8] - s8[max(k - 8, 1)] * s8[8]) for k in 1:16};
  Real s16[16] = {noEvent(if k <= 8 then s8[k] else s8[max(k - 8, 1)] * c8[8] + c8[max(k - 8, 1)] * s8[8]) for k in 1:16};
equation
  c = {noEvent(if k <= 16 then c16[k] else c16[max(k - 16, 1)] * c16[16] - s16[max(k - 16, 1)] * s16[16]) for k in 1:32};
  s = {noEvent(if k <= 16 then s16[k] else s16[max(k - 16, 1)] * c16[16] + c16[max(k - 16, 1)] * s16[16]) for k in 1:32};
end Harmonics;
