"""Energy and entropy of the two thermo-spring system under EEM and IDA, side by side.

    PYTHONPATH=build/python python3 python/examples/plot_energy_entropy.py [out.png]

EEM keeps the energy of this isolated system to round-off and its entropy never decreases;
IDA keeps both to its tolerance only. Writes energy_entropy.png (or the path given)."""
import pathlib
import sys

import matplotlib

matplotlib.use("Agg")  # no display needed
import matplotlib.pyplot as plt  # noqa: E402

import metriplex  # noqa: E402

scene = pathlib.Path(__file__).resolve().parents[2] / "scenes" / "two_thermo_springs.xml"
runs = {
    "EEM, dt = 0.2": metriplex.run(str(scene), integrator="eem", dt=0.2, t_end=100),
    "IDA, rtol = 1e-4": metriplex.run(str(scene), integrator="ida", rtol=1e-4, dt_out=0.2, t_end=100),
}

figure, (energy, entropy) = plt.subplots(2, 1, sharex=True, figsize=(8, 6))
for label, r in runs.items():
    h = r.history
    energy.semilogy(h["time"][1:], abs(h["energy"][1:] - h["energy"][0]) / h["energy"][0] + 1e-17, label=label)
    entropy.plot(h["time"], h["entropy"], label=label)
    print(f"{label}: {r.summary['steps']} steps, {r.summary['wall_seconds']:.3f} s, "
          f"energy drift {r.summary['max_relative_energy_drift']:.2e}")
energy.set_ylabel("|E - E0| / E0")
entropy.set_ylabel("S [J/K]")
entropy.set_xlabel("time [s]")
energy.legend()
energy.set_title("Two thermo-springs: energy drift and entropy")
output = sys.argv[1] if len(sys.argv) > 1 else "energy_entropy.png"
figure.savefig(output, dpi=120)
print(f"wrote {output}")
