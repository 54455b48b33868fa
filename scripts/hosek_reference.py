#!/usr/bin/env python3
"""Reference values of the Hosek-Wilkie spectral sky and sun (version 1.4a), for
the tests of src/light/sky/.

Usage (from the repository root):
    python3 scripts/hosek_reference.py ../shared/data/hosek-wilkie/ArHosekSkyModelData_Spectral.h

A deliberately plain, double-precision evaluation of the published model,
independent of the Rust code and of scripts/hosek_data.py: it reads the
coefficient arrays straight from the authors' .h file and evaluates the formulas
of Hosek & Wilkie 2012 (sky) and 2013 (sun) term by term as written there:
per-term Bezier weights, the textbook Mie denominator 1 + H^2 - 2 H cos(gamma),
a lookup of the solar pieces written afresh. Prints Rust table rows:

- SKY: (turbidity, albedo, sun elevation [rad], theta, gamma, [11 channels])
  for turbidity {2, 5, 9} x elevation {5, 30, 60} deg x albedo {0, 0.5} at the
  zenith and at the horizon 0, 90 and 180 deg of azimuth from the sun, and at
  theta 60 deg, 30 deg of azimuth from the sun.
- SKY_BINS: the same at the renderer's 36 bins (380..730 nm), linear in
  wavelength between channels, 720 nm held at 730 nm, for a few cases.
- SUN: (turbidity, sun elevation, [36 bins], [36 bins]) the sun's spectral
  irradiance on a surface facing the zenith, E = integral over the disk of
  L_sun cos(theta) d(omega), and on a surface facing the sun (cos(gamma) in
  place of cos(theta)), by Gauss-Legendre x trapezoid quadrature over the disk;
  and SUN_POINT:
  the sun's radiance at a few points of the disk.

Every angle is printed with 9 significant digits and evaluated at the printed
value, so the Rust test evaluates at the same arguments (up to f32 rounding).
Standard library only.
"""

import math
import sys

WAVELENGTHS = [320 + 40 * k for k in range(11)]
SOLAR_RADIUS = math.radians(0.51) / 2.0  # the model's TERRESTRIAL_SOLAR_RADIUS


def read_arrays(path):
    """Every `double name[] = { ... };` in the file, by scanning lines."""
    arrays, name, values = {}, None, None
    with open(path, encoding="utf-8") as f:
        for line in f:
            line = line.split("//")[0].strip()
            if name is None:
                if line.startswith("double") and "[]" in line and "*" not in line:
                    name = line.split()[1].split("[")[0]
                    values = []
                    line = line.split("=", 1)[1] if "=" in line else ""
                else:
                    continue
            done = "}" in line
            line = line.replace("{", " ").replace("}", " ").replace(";", " ")
            for tok in line.split(","):
                tok = tok.strip()
                if tok:
                    values.append(float(tok))
            if done:
                arrays[name] = values
                name = None
    return arrays


def g9(x):
    return float(f"{x:.9g}")


class Sky:
    def __init__(self, arrays, turbidity, albedo, elevation):
        self.a = arrays
        self.turbidity, self.albedo, self.elevation = turbidity, albedo, elevation
        self.configs = [self.cook(arrays[f"dataset{w}"], 9) for w in WAVELENGTHS]
        self.radiances = [self.cook(arrays[f"datasetRad{w}"], 1)[0] for w in WAVELENGTHS]

    def cook(self, data, n):
        """The n parameters: quintic Bezier in (elevation / (pi/2))^(1/3), linear in turbidity and albedo."""
        x = (self.elevation / (math.pi / 2)) ** (1.0 / 3.0)
        weights = [math.comb(5, k) * (1 - x) ** (5 - k) * x ** k for k in range(6)]
        t_int = int(self.turbidity)
        t_rem = self.turbidity - t_int
        out = [0.0] * n
        for alb, wa in ((0, 1 - self.albedo), (1, self.albedo)):
            for t, wt in ((t_int, 1 - t_rem), (t_int + 1, t_rem)):
                if t > 10 or wt == 0.0:
                    continue
                start = n * 6 * (10 * alb + t - 1)
                for k in range(6):
                    for j in range(n):
                        out[j] += wa * wt * weights[k] * data[start + n * k + j]
        return out

    def channel(self, k, theta, gamma):
        A, B, C, D, E, F, G, I, H = self.configs[k]  # stored order: A B C D E F G I H
        chi = (1 + math.cos(gamma) ** 2) / (1 + H * H - 2 * H * math.cos(gamma)) ** 1.5
        ct = max(math.cos(theta), 0.0)
        perez = (1 + A * math.exp(B / (ct + 0.01))) * (
            C + D * math.exp(E * gamma) + F * math.cos(gamma) ** 2 + G * chi + I * math.sqrt(ct))
        return perez * self.radiances[k]

    def at_nm(self, lam, values):
        """Linear between channel values; 720 nm held beyond."""
        if lam >= 720:
            return values[10]
        pos = (lam - 320) / 40.0
        lo = int(pos)
        t = pos - lo
        return (1 - t) * values[lo] + t * values[lo + 1]

    # The sun (2013): per turbidity, a piecewise cubic in elevation times limb darkening.
    def solar_piece(self, t_index, k, elevation):
        data = self.a[f"solarDataset{WAVELENGTHS[k]}"]
        piece = min(int(45 * (elevation / (math.pi / 2)) ** (1.0 / 3.0)), 44)
        x = elevation - (math.pi / 2) * (piece / 45.0) ** 3
        c3, c2, c1, c0 = data[180 * t_index + 4 * piece: 180 * t_index + 4 * piece + 4]
        return c0 + c1 * x + c2 * x ** 2 + c3 * x ** 3

    def sun(self, lam, theta, gamma):
        if gamma > SOLAR_RADIUS or theta > math.pi / 2:
            return 0.0
        elevation = max(math.pi / 2 - theta, 0.0)
        if lam >= 720:
            lo, w = 9, 1.0
        else:
            lo, w = int((lam - 320) // 40), ((lam - 320) % 40) / 40.0
        t_lo = int(self.turbidity) - 1
        t_w = self.turbidity - int(self.turbidity)
        if t_lo == 9:
            t_lo, t_w = 8, 1.0
        direct = 0.0
        for t, wt in ((t_lo, 1 - t_w), (t_lo + 1, t_w)):
            direct += wt * ((1 - w) * self.solar_piece(t, lo, elevation) + w * self.solar_piece(t, lo + 1, elevation))
        ld_lo = self.a[f"limbDarkeningDataset{WAVELENGTHS[lo]}"]
        ld_hi = self.a[f"limbDarkeningDataset{WAVELENGTHS[lo + 1]}"]
        s2 = 1 - (math.sin(gamma) / math.sin(SOLAR_RADIUS)) ** 2
        mu = math.sqrt(max(s2, 0.0))
        dark = sum(((1 - w) * ld_lo[i] + w * ld_hi[i]) * mu ** i for i in range(6))
        return max(direct * dark, 0.0)


def gauss_legendre(n):
    """Nodes and weights on [-1, 1] (Newton on the Legendre polynomial)."""
    nodes, weights = [], []
    for i in range(1, n + 1):
        x = math.cos(math.pi * (i - 0.25) / (n + 0.5))
        for _ in range(100):
            p0, p1 = 1.0, x
            for k in range(2, n + 1):
                p0, p1 = p1, ((2 * k - 1) * x * p1 - (k - 1) * p0) / k
            dp = n * (x * p1 - p0) / (x * x - 1)
            dx = p1 / dp
            x -= dx
            if abs(dx) < 1e-15:
                break
        nodes.append(x)
        weights.append(2 / ((1 - x * x) * dp * dp))
    return nodes, weights


def sun_irradiance(sky, lams, normal, n_alpha=48, n_phi=96):
    """E(lam) = integral over the disk of L_sun cos(theta) d(omega), on the horizontal;
    or of L_sun cos(gamma) d(omega) on a surface facing the sun if `normal`.

    Around the sun's direction: gamma from sin(gamma) = sin(R) sin(alpha), alpha in [0, pi/2]
    (so the limb cosine is cos(alpha), smooth), d(omega) = tan(gamma) sin(R) cos(alpha) d(alpha) d(phi).
    """
    theta_s = math.pi / 2 - sky.elevation
    nodes, weights = gauss_legendre(n_alpha)
    total = [0.0] * len(lams)
    for xn, wn in zip(nodes, weights):
        alpha = (xn + 1) * math.pi / 4
        w_alpha = wn * math.pi / 4
        gamma = math.asin(math.sin(SOLAR_RADIUS) * math.sin(alpha))
        jac = math.tan(gamma) * math.sin(SOLAR_RADIUS) * math.cos(alpha)
        for j in range(n_phi):
            phi = 2 * math.pi * (j + 0.5) / n_phi
            cos_t = math.cos(theta_s) * math.cos(gamma) + math.sin(theta_s) * math.sin(gamma) * math.cos(phi)
            theta = math.acos(max(-1.0, min(1.0, cos_t)))
            if cos_t <= 0:
                continue
            dw = w_alpha * (2 * math.pi / n_phi) * jac
            for i, lam in enumerate(lams):
                total[i] += sky.sun(lam, theta, gamma) * (math.cos(gamma) if normal else cos_t) * dw
    return total


def fmt(values):
    return ", ".join(f"{v:.9e}" for v in values)


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    arrays = read_arrays(sys.argv[1])
    bins = [380 + 10 * i for i in range(36)]
    print(f"// python3 scripts/hosek_reference.py ArHosekSkyModelData_Spectral.h (solar radius {SOLAR_RADIUS!r} rad)")
    print("// SKY: (turbidity, albedo, sun elevation, theta, gamma, [320, 360, ..., 720 nm])")
    for turbidity in (2.0, 5.0, 9.0):
        for elev_deg in (5.0, 30.0, 60.0):
            for albedo in (0.0, 0.5):
                elevation = g9(math.radians(elev_deg))
                sky = Sky(arrays, turbidity, albedo, elevation)
                theta_s = math.pi / 2 - elevation
                dirs = [(0.0, 0.0)] + [(math.pi / 2, az) for az in (0.0, 90.0, 180.0)] + [(math.radians(60), 30.0)]
                for theta, az in dirs:
                    theta = g9(theta)
                    cg = math.cos(theta) * math.cos(theta_s) + math.sin(theta) * math.sin(theta_s) * math.cos(math.radians(az))
                    gamma = g9(math.acos(max(-1.0, min(1.0, cg))))
                    values = [sky.channel(k, theta, gamma) for k in range(11)]
                    print(f"({turbidity}, {albedo}, {elevation!r}, {theta!r}, {gamma!r}, [{fmt(values)}]),")
    print("// SKY_BINS: (turbidity, albedo, sun elevation, theta, gamma, [380, 390, ..., 730 nm])")
    for turbidity, albedo, elev_deg, theta, gamma in ((3.5, 0.3, 20.0, 0.7, 0.4), (7.25, 1.0, 45.0, 1.5, 2.5), (10.0, 0.0, 90.0, 1.2, 1.2)):
        elevation = g9(math.radians(elev_deg))
        sky = Sky(arrays, turbidity, albedo, elevation)
        ch = [sky.channel(k, theta, gamma) for k in range(11)]
        print(f"({turbidity}, {albedo}, {elevation!r}, {theta!r}, {gamma!r}, [{fmt(sky.at_nm(l, ch) for l in bins)}]),")
    print("// SUN: (turbidity, sun elevation, [irradiance at 380, 390, ..., 730 nm: horizontal], [facing the sun])")
    for turbidity in (2.0, 5.0, 9.0):
        for elev_deg in (5.0, 30.0, 60.0):
            elevation = g9(math.radians(elev_deg))
            sky = Sky(arrays, turbidity, 0.0, elevation)
            horizontal, normal = sun_irradiance(sky, bins, False), sun_irradiance(sky, bins, True)
            print(f"({turbidity}, {elevation!r}, [{fmt(horizontal)}], [{fmt(normal)}]),")
    print("// SUN_POINT: (turbidity, sun elevation, theta, gamma, [radiance at 380, 390, ..., 730 nm])")
    for turbidity, elev_deg, d_theta, gamma_frac in ((2.0, 30.0, 0.0, 0.0), (6.5, 10.0, 0.5, 0.5), (9.0, 60.0, -0.3, 0.95)):
        elevation = g9(math.radians(elev_deg))
        sky = Sky(arrays, turbidity, 0.0, elevation)
        gamma = g9(gamma_frac * SOLAR_RADIUS)
        theta = g9(math.pi / 2 - elevation + d_theta * SOLAR_RADIUS)
        print(f"({turbidity}, {elevation!r}, {theta!r}, {gamma!r}, [{fmt(sky.sun(l, theta, gamma) for l in bins)}]),")


if __name__ == "__main__":
    main()
