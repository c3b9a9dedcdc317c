"""Derive the PMMA absorption tables of materials/ (run: python3 pmma_absorption.py).

Input: the PMMA polymer-optical-fibre attenuation spectrum as digitized in
ander-vieira/fiberSimulations, csv/attenuationPMMA.csv (relative values; that project
scales it to 0.08 dB/m at 500 nm, matlab/attenuationPMMA.m). Output: rows [nm, 1/mm]
for 400-781 nm, (a) fibre grade: 0.08 dB/m at 500 nm, (b) light-guide grade: the same
shape scaled so its mean over 400-700 nm is the ACRYLITE figure for colourless sheet,
0.5 % absorbed per inch: -ln(1 - 0.005) / 25.4 mm.
"""
import math

CSV = """400,0.04625
414.52,0.035735
427.68,0.029238
440.38,0.024619
455.35,0.020532
475.32,0.017453
488.93,0.016169
497.55,0.016015
507.08,0.016169
518.42,0.017288
526.13,0.018308
532.49,0.019761
539.29,0.022162
543.83,0.023695
547.46,0.023924
552,0.023695
557.44,0.021332
560.62,0.019761
565.15,0.018134
570.6,0.016481
576.5,0.015713
579.67,0.015415
584.21,0.016015
588.29,0.017124
592.38,0.019952
597.82,0.026574
603.72,0.043259
609.62,0.06843
613.7,0.084438
618.24,0.099327
621.42,0.10319
623.23,0.10419
627.31,0.10125
630.04,0.094697
633.21,0.084438
637.3,0.067133
642.29,0.050404
645.46,0.042439
648.19,0.038206
650,0.036774
653.18,0.035735
656.35,0.036774
661.34,0.041638
666.33,0.050404
669.51,0.05707
670.87,0.059292
674.5,0.062195
679.04,0.064617
683.58,0.067781
687.21,0.073162
692.2,0.088566
697.19,0.12256
702.18,0.20728
708.98,0.36425
713.52,0.47594
718.97,0.57068
721.69,0.59863
723.96,0.60436
727.13,0.59295
730.31,0.55991
735.3,0.44945
740.74,0.33743
746.64,0.25335
751.63,0.20728
756.17,0.18483
758.44,0.17621
759.8,0.17287
762.07,0.16961
765.7,0.1779
769.78,0.20143
776.13,0.27087
781.13,0.33743"""

rows = [tuple(map(float, line.split(","))) for line in CSV.splitlines()]


def at(nm):
    """Linear between rows (blutrace reads tables linearly)."""
    for (a, fa), (b, fb) in zip(rows, rows[1:]):
        if a <= nm <= b:
            return fa + (nm - a) / (b - a) * (fb - fa)
    raise ValueError(nm)


fibre = 0.08 * math.log(10) / 10 / 1000 / at(500.0)  # 0.08 dB/m at 500 nm, in 1/mm
mean = sum(at(nm) for nm in range(400, 701)) / 301
lgp = -math.log(1 - 0.005) / 25.4 / mean
for name, k in (("fibre grade", fibre), ("light-guide grade", lgp)):
    print(f"# {name}: factor {k:.6e} /mm per csv unit; at 450/550/650 nm: "
          + ", ".join(f"{k * at(nm):.3e}" for nm in (450, 550, 650)))
    print("[" + ", ".join(f"[{nm:g}, {k * v:.3e}]" for nm, v in rows) + "]")
