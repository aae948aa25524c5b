#!/usr/bin/env python3
"""Independent reference values for tests/tyre_pacejka.rs.

Written separately from crates/vehsim-core/src/tyre/pacejka.rs, straight from the PAC2002 equations in Pacejka,
Tyre and Vehicle Dynamics 2nd ed., section 4.3.2 (4.E1-4.E30 pure slip, 4.E50-4.E67 combined).
Run: python3 tests/data/pac2002_reference.py ; the printed numbers are pasted into the test.

Conventions: the files are ISO/TYDEX (PKY1 < 0): vehsim's alpha maps to alpha_file = -alpha and
Fy is taken as is. Camber 0, all scaling factors 1 except LFZO and the friction scales given.
"""
import math


def sedan():
    # Numbers typed from tests/data/tir/Sedan_Pac02Tire.tir (public Project Chrono file; see its README).
    return dict(FNOMIN=4850, LFZO=0.81,
                PCX1=1.6411, PDX1=1.1739, PDX2=-0.16395, PEX1=0.46403, PEX2=0.25022, PEX3=0.067842,
                PEX4=-3.7604e-005, PKX1=22.303, PKX2=0.48896, PKX3=0.21253, PHX1=0.0012297,
                PHX2=0.0004318, PVX1=-8.8098e-006, PVX2=1.862e-005,
                PCY1=1.3507, PDY1=1.0489, PDY2=-0.18033, PEY1=-0.0074722, PEY2=-0.0063208,
                PEY3=-9.9935, PKY1=-21.92, PKY2=2.0012, PHY1=0.0026747, PHY2=8.9094e-005,
                PVY1=0.037318, PVY2=-0.010049)


def own():
    # vehicles/tyres/srtt_p225_60r16.tir (vehsim's own file).
    return dict(FNOMIN=4000, LFZO=1.0, PCX1=1.5, PDX1=1.2, PDX2=-0.08, PEX1=0.5, PEX2=0.1,
                PKX1=22, PCY1=1.35, PDY1=1.0, PDY2=-0.10, PEY1=-0.5, PKY1=-20, PKY2=2.0,
                RBX1=12, RBX2=10, RCX1=1.0, RBY1=9, RBY2=8, RCY1=1.0)


def own_mz():
    # own() plus the .tir's aligning coefficients, and three overrides the test sets so that every
    # term of the combined Mz is exercised (the file has no residual torque and no s arm):
    # QDZ6 = 0.003, SSZ1 = 0.02, SSZ2 = 0.03.
    c = own()
    c.update(UNLOADED_RADIUS=0.338, QBZ1=10, QBZ2=-1.5, QBZ9=8, QCZ1=1.2, QDZ1=0.09, QDZ2=-0.008,
             QEZ1=-1.5, QEZ2=0.3, QDZ6=0.003, SSZ1=0.02, SSZ2=0.03)
    return c


def mz_combined(c, fz, kappa, alpha_file):
    """PAC2002 aligning moment with combined slip (4.E71-4.E78): Mz = -t Fy' + Mzr + s Fx.

    No shifts (SHy = SVy = SHt = 0), camber 0, all scales 1, mu_surface = mu_reference."""
    fz0 = c['FNOMIN'] * g(c, 'LFZO', 1.0)
    dfz = (fz - fz0) / fz0
    r0 = c['UNLOADED_RADIUS']
    kx = fz * (c['PKX1'] + g(c, 'PKX2') * dfz) * math.exp(g(c, 'PKX3') * dfz)
    ky = c['PKY1'] * fz0 * math.sin(2 * math.atan(fz / (c['PKY2'] * fz0)))
    ratio = kx / ky

    def equiv(a):
        sgn = 1.0 if a >= 0 else -1.0
        return math.atan(math.sqrt(math.tan(a) ** 2 + (ratio * kappa) ** 2)) * sgn

    at_eq = equiv(alpha_file)
    ar_eq = equiv(alpha_file)
    bt = g(c, 'QBZ1') + g(c, 'QBZ2') * dfz + g(c, 'QBZ3') * dfz ** 2
    ct = c['QCZ1']
    dt = fz * (c['QDZ1'] + g(c, 'QDZ2') * dfz) * (r0 / fz0)
    et = min(g(c, 'QEZ1') + g(c, 'QEZ2') * dfz + g(c, 'QEZ3') * dfz ** 2, 1.0)
    t = dt * math.cos(ct * math.atan(bt * at_eq - et * (bt * at_eq - math.atan(bt * at_eq)))) * math.cos(alpha_file)
    br = g(c, 'QBZ9')  # QBZ10 = 0
    dr = fz * (g(c, 'QDZ6') + g(c, 'QDZ7') * dfz) * r0
    mzr = dr * math.cos(math.atan(br * ar_eq)) * math.cos(alpha_file)
    fx, fy = combined_own(c, fz, kappa, alpha_file)  # no RVY: Fy' = Fy
    s = r0 * (g(c, 'SSZ1') + g(c, 'SSZ2') * fy / fz0)
    return -t * fy + mzr + s * fx


def g(c, k, d=0.0):
    return c.get(k, d)


def fx0(c, fz, kappa, lmux=1.0, lkx=1.0):
    fz0 = c['FNOMIN'] * g(c, 'LFZO', 1.0)
    dfz = (fz - fz0) / fz0
    shx = g(c, 'PHX1') + g(c, 'PHX2') * dfz
    kx = kappa + shx
    C = c['PCX1']
    mu = (c['PDX1'] + g(c, 'PDX2') * dfz) * lmux
    D = mu * fz
    E = (g(c, 'PEX1') + g(c, 'PEX2') * dfz + g(c, 'PEX3') * dfz ** 2) * (1 - g(c, 'PEX4') * (1 if kx >= 0 else -1))
    E = min(E, 1.0)
    K = fz * (c['PKX1'] + g(c, 'PKX2') * dfz) * math.exp(g(c, 'PKX3') * dfz) * lkx
    B = K / (C * D)
    svx = fz * (g(c, 'PVX1') + g(c, 'PVX2') * dfz) * lmux
    return D * math.sin(C * math.atan(B * kx - E * (B * kx - math.atan(B * kx)))) + svx


def fy0(c, fz, alpha_file, lmuy=1.0, lky=1.0):
    fz0 = c['FNOMIN'] * g(c, 'LFZO', 1.0)
    dfz = (fz - fz0) / fz0
    shy = g(c, 'PHY1') + g(c, 'PHY2') * dfz
    ay = alpha_file + shy
    C = c['PCY1']
    mu = (c['PDY1'] + g(c, 'PDY2') * dfz) * lmuy
    D = mu * fz
    E = (g(c, 'PEY1') + g(c, 'PEY2') * dfz) * (1 - g(c, 'PEY3') * (1 if ay >= 0 else -1))
    E = min(E, 1.0)
    K = c['PKY1'] * fz0 * math.sin(2 * math.atan(fz / (c['PKY2'] * fz0))) * lky
    B = K / (C * D)
    svy = fz * (g(c, 'PVY1') + g(c, 'PVY2') * dfz) * lmuy
    return D * math.sin(C * math.atan(B * ay - E * (B * ay - math.atan(B * ay)))) + svy


def combined_own(c, fz, kappa, alpha_file):
    # RHX1 = RHY1 = RHY2 = 0, REX = REY = 0, no RVY: Gxa = cos(RCX1 atan(Bxa alpha)), etc.
    bxa = c['RBX1'] * math.cos(math.atan(c['RBX2'] * kappa))
    gxa = math.cos(c['RCX1'] * math.atan(bxa * alpha_file))
    byk = c['RBY1'] * math.cos(math.atan(c['RBY2'] * alpha_file))
    gyk = math.cos(c['RCY1'] * math.atan(byk * kappa))
    return gxa * fx0(c, fz, kappa), gyk * fy0(c, fz, alpha_file)


if __name__ == '__main__':
    s = sedan()
    print('# Sedan_Pac02Tire.tir, mu_surface = mu_reference = 1')
    for fz in (2000.0, 4850.0, 8000.0):
        for kappa in (0.02, 0.1, -0.1):
            print(f'fx fz={fz} kappa={kappa}: {fx0(s, fz, kappa)!r}')
        for alpha in (0.02, 0.1, -0.1):  # vehsim alpha; file alpha = -alpha
            print(f'fy fz={fz} alpha={alpha}: {fy0(s, fz, -alpha)!r}')
    o = own()
    print('# vehsim srtt_p225_60r16.tir, mu_surface = 1, stiffness exponent irrelevant at mu 1')
    for fz in (2000.0, 4000.0, 8000.0):
        print(f'fx fz={fz} kappa=0.05: {fx0(o, fz, 0.05)!r}')
        print(f'fy fz={fz} alpha=0.05: {fy0(o, fz, -0.05)!r}')
        fx, fy = combined_own(o, fz, 0.05, -0.05)
        print(f'combined fz={fz} kappa=0.05 alpha=0.05: fx={fx!r} fy={fy!r}')
    m = own_mz()
    print('# Mz, combined slip, srtt .tir + QDZ6 0.003, SSZ1 0.02, SSZ2 0.03, mu 1')
    for fz in (2000.0, 4000.0, 8000.0):
        for kappa, alpha in ((0.0, 0.05), (0.05, 0.05), (0.1, 0.0873), (-0.1, 0.05), (0.02, -0.1), (0.3, 0.02)):
            print(f'mz fz={fz} kappa={kappa} alpha={alpha}: {mz_combined(m, fz, kappa, -alpha)!r}')
    # Ice: mu_surface 0.15 on mu_reference 1.0 with stiffness exponent 0.5 -> LMU 0.15, LK sqrt(0.15)
    r = 0.15
    print(f'ice fx fz=4000 kappa=0.07: {fx0(o, 4000.0, 0.07, lmux=r, lkx=math.sqrt(r))!r}')
    print(f'ice fy fz=4000 alpha=0.05: {fy0(o, 4000.0, -0.05, lmuy=r, lky=math.sqrt(r))!r}')
