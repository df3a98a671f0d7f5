# An awk function the report scripts share (scripts/convergence_report.sh,
# scripts/fastest_report.sh): the 95% two-sided Student t quantile for k - 1
# degrees of freedom, k the number of seeds.
function t95(k) {
  if (k <= 2) return 12.706; if (k == 3) return 4.303; if (k == 4) return 3.182; if (k == 5) return 2.776
  if (k == 6) return 2.571; if (k == 7) return 2.447; if (k == 8) return 2.365; if (k <= 11) return 2.262
  if (k <= 21) return 2.086; return 1.96
}
