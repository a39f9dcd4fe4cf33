"""The paper's Fig. 5 (Dimitrakopoulos, Makris & Kappos 2010): pounding
spectra Pi1 = umax wp^2 / ap against Pi2 = Tp / T0 under one-sine pulses,
normal and reverse, for Pi3 = 0.01 ... 2, eps = 0.5, xi = 0.05, from the
event-driven reference -- the spectra of docs/paper.md ("Figs. 5 and 6",
scripts/paper.sh), in a few lines.

    python3 paper_spectrum.py [out.png] [npi2]
"""
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import pound  # noqa: E402

out = sys.argv[1] if len(sys.argv) > 1 else "paper-fig5.png"
npi2 = int(sys.argv[2]) if len(sys.argv) > 2 else 120
Pi3 = [0.01, 0.1, 0.5, 1, 2]

# = pound spectrum --pulse sine --dir normal,reverse --Pi3 0.01,0.1,0.5,1,2 --eps 0.5
#                  --Pi2 0.05:5:120 --method event
s = pound.spectrum(Pi2_range=(0.05, 5, npi2), pulse="sine", dir=["normal", "reverse"],
                   Pi3=Pi3, eps=0.5, method="event")

fig, axes = plt.subplots(1, 2, figsize=(11, 4.5), sharey=True)
for k, curve in enumerate(s.curves):  # curves: dir slowest, Pi3 fastest
    ax = axes[0 if curve.dir == "normal" else 1]
    ax.loglog(s.Pi2, s.Pi1[k], lw=1.5, label="$\\Pi_3$ = %g" % curve.Pi3)
for ax, d in zip(axes, ("normal", "reverse")):
    ax.set_title("one-sine pulse, %s (eps = 0.5, xi = 0.05)" % d)
    ax.set_xlabel("$\\Pi_2 = T_p / T_0$")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(loc="lower left")
axes[0].set_ylabel("$\\Pi_1 = u_{max}\\, \\omega_p^2 / a_p$")
fig.suptitle("Fig. 5: pounding spectra in $\\Pi$ terms (event-driven reference)")
fig.tight_layout()
fig.savefig(out, dpi=120)
print("%s: %d curves x %d Pi2, max Pi1 = %.4g (normal), %.4g (reverse)"
      % (out, len(s.curves), npi2, s.Pi1[:5].max(), s.Pi1[5:].max()))
