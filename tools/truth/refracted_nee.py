"""Refracted next-event estimation: the truth of a medium behind a smooth dielectric boundary
lit by point lights, which Mitsuba's `volpath` cannot render (its shadow rays stop at a smooth
dielectric, ../../shared/truth-notes.md).

A Mitsuba `SamplingIntegrator` written in Python (drjit, `llvm_ad_rgb`) for one scene shape:
ONE analytic sphere (centre c, radius R) filled with a homogeneous medium (sigma_t, albedo and
Henyey-Greenstein g per scene unit) behind a smooth boundary of relative index eta (1 <= eta < 2),
point lights outside it, and a constant (or no) environment. `truth.py --integrator
refracted-nee` uses it; lucent_to_mitsuba.py's `RefractedNeeScene` says which scenes qualify.

Per camera ray:
  - Miss: the environment (truth.py replaces what is seen there by lucent's `sky`, as for
    volpath).
  - Hit: the camera ray's own specular reflection off the boundary is NOT counted (lucent's
    truth scenes have specular 0: the truth holds the light that went through the medium;
    `--with-camera-reflection` counts the environment's reflection there). The ray refracts in
    with weight (1 - F) / eta^2 (radiance leaving a medium of index eta: L_out = (1 - F)
    L_in / eta^2).
  - Inside: free flights sampled with one channel chosen per event, weighted by the balance
    heuristic over channels (Mitsuba volpath's spectral MIS: weight sigma_s T / mean(sigma_t
    T), escape T / mean(T)); HG phase sampled exactly. At the boundary: Fresnel reflection with
    probability F (total internal reflection included), else the path refracts out (weight
    eta^2) into the environment, which it reaches without another hit (a lone convex shape).
  - Next-event estimation at every scattering vertex x, to every point light y: the entry point
    p on the sphere with Snell's law (Fermat's principle: the stationary point of the optical
    path eta |x - p| + |p - y| on the great circle through x and y, by bisection on its
    derivative; unique for eta < 2: a ball lens of index < 2 focuses outside itself), and the
    irradiance at x across the refracted beam
        E = I (1 - F(p)) exp(-sigma_t |x - p|) / J,   J = dA_perp(x) / dOmega(light),
    J from central differences of four rays traced from the light (perturbed by 1e-3 rad),
    refracted at the sphere and cut by the plane through x across the beam (at eta = 1, J =
    |x - y|^2). L += throughput x phase x E. Where x lies outside the region the refracted
    light reaches directly (beyond the envelope of the grazing rays) the bisection ends at the
    edge of the visible cap without satisfying Snell's law: no connection (checked by the
    refracted direction, within 1e-3).
  - Not sampled: light that reaches a scattering vertex after an internal reflection but before
    any scattering (the light would have to cross the sphere unscattered: transmittance below
    e^-15 for Jensen's media at 20 mm; noted in README).
"""

from __future__ import annotations

import math

import drjit as dr
import mitsuba as mi


class RefractedNee(mi.SamplingIntegrator):
    """See the module docs. Configure with `configure(...)` after construction."""

    def __init__(self, props=mi.Properties()):
        super().__init__(props)
        self.centre = mi.ScalarPoint3f(0, 0, 0)
        self.radius = 1.0
        self.eta = 1.0
        self.sigma_t = mi.ScalarColor3f(1, 1, 1)
        self.albedo = mi.ScalarColor3f(0, 0, 0)
        self.g = 0.0
        self.lights = []  # (position ScalarPoint3f, intensity ScalarColor3f)
        self.camera_reflection = False
        self.delta = 1e-3

    def configure(self, centre, radius, eta, sigma_t, albedo, g, lights, camera_reflection=False):
        if not (1.0 <= eta < 2.0):
            raise ValueError(f"refracted NEE needs 1 <= eta < 2 (got {eta}): at eta >= 2 the "
                             "sphere focuses light inside itself and the connection is not unique")
        self.centre = mi.ScalarPoint3f(*[float(v) for v in centre])
        self.radius = float(radius)
        self.eta = float(eta)
        self.sigma_t = mi.ScalarColor3f(*[float(v) for v in sigma_t])
        self.albedo = mi.ScalarColor3f(*[float(v) for v in albedo])
        self.g = float(g)
        self.lights = [(mi.ScalarPoint3f(*[float(v) for v in p]),
                        mi.ScalarColor3f(*[float(v) for v in i])) for p, i in lights]
        self.camera_reflection = bool(camera_reflection)

    def aov_names(self):
        return []

    def to_string(self):
        return "RefractedNee[]"

    # -- geometry ---------------------------------------------------------------------------

    def _hit_from_outside(self, o, d):
        """(t, hit) of the ray o + t d (d unit) entering the sphere."""
        oc = o - self.centre
        b = dr.dot(oc, d)
        cc = dr.squared_norm(oc) - self.radius * self.radius
        disc = b * b - cc
        t = -b - dr.safe_sqrt(disc)
        return t, (disc > 0) & (t > 0)

    def _exit_from_inside(self, o, d):
        oc = o - self.centre
        b = dr.dot(oc, d)
        cc = dr.squared_norm(oc) - self.radius * self.radius
        return dr.maximum(-b + dr.safe_sqrt(b * b - cc), 0.0)

    def _refract_in(self, w, n):
        """w (propagating, from outside) refracted through normal n (outward, n.w < 0)."""
        inv = 1.0 / self.eta
        cos_i = -dr.dot(n, w)
        sin2_t = inv * inv * dr.maximum(1.0 - cos_i * cos_i, 0.0)
        return dr.normalize(inv * w + (inv * cos_i - dr.safe_sqrt(1.0 - sin2_t)) * n)

    def _beam_point(self, y, w, x, d0):
        """The ray from the light y along w, refracted at the sphere, cut by the plane through x
        across d0; and whether it hit."""
        t, hit = self._hit_from_outside(y, w)
        q = y + t * w
        n = dr.normalize(q - self.centre)
        wt = self._refract_in(w, n)
        s = dr.dot(x - q, d0) / dr.dot(wt, d0)
        return q + s * wt, hit

    def _connect(self, x, y):
        """Refracted connection from the interior point x to the light at y: (p, valid)."""
        c = self.centre
        R = self.radius
        eta = self.eta
        to_y = y - c
        D = dr.norm(to_y)
        e1 = to_y / D
        xc = x - c
        x1 = dr.dot(xc, e1)
        perp = xc - x1 * e1
        x2 = dr.norm(perp)
        # Any unit vector across e1 when x lies on the axis (then p = c + R e1).
        fallback = mi.Frame3f(e1).s
        e2 = dr.select(x2 > 1e-7 * R, perp / dr.maximum(x2, 1e-30), fallback)
        theta_x = dr.atan2(x2, x1)
        theta_vis = dr.acos(dr.clip(R / D, -1.0, 1.0))
        lo = mi.Float(0.0)
        hi = dr.minimum(theta_x, theta_vis)
        # d/dtheta of eta |x - p| + |p - y| with p = R (cos, sin) in the (e1, e2) plane.
        for _ in range(30):
            mid = 0.5 * (lo + hi)
            s, co = dr.sincos(mid)
            px, py = R * co, R * s
            dpx, dpy = -R * s, R * co
            ax, ay = px - x1, py - x2
            bx, by = px - D, py
            la = dr.maximum(dr.sqrt(ax * ax + ay * ay), 1e-30)
            lb = dr.maximum(dr.sqrt(bx * bx + by * by), 1e-30)
            deriv = eta * (ax * dpx + ay * dpy) / la + (bx * dpx + by * dpy) / lb
            neg = deriv < 0
            lo = dr.select(neg, mid, lo)
            hi = dr.select(neg, hi, mid)
        theta = 0.5 * (lo + hi)
        s, co = dr.sincos(theta)
        p = c + R * (co * e1 + s * e2)
        return p

    # -- the estimator ------------------------------------------------------------------------

    def _hg(self, cos_theta):
        g = self.g
        denom = 1.0 + g * g - 2.0 * g * cos_theta
        return (1.0 - g * g) / (4.0 * math.pi * denom * dr.safe_sqrt(denom))

    def _sample_hg(self, d, u1, u2):
        g = self.g
        if abs(g) < 1e-3:
            cos_theta = 1.0 - 2.0 * u1
        else:
            sq = (1.0 - g * g) / (1.0 - g + 2.0 * g * u1)
            cos_theta = (1.0 + g * g - sq * sq) / (2.0 * g)
        cos_theta = dr.clip(cos_theta, -1.0, 1.0)
        sin_theta = dr.safe_sqrt(1.0 - cos_theta * cos_theta)
        s, c = dr.sincos(2.0 * math.pi * u2)
        frame = mi.Frame3f(d)
        return dr.normalize(frame.to_world(mi.Vector3f(sin_theta * c, sin_theta * s, cos_theta)))

    def _nee(self, x, d):
        """Sum over point lights of phase x irradiance at x through the refracting boundary."""
        total = mi.Spectrum(0.0)
        for position, intensity in self.lights:
            y = mi.Point3f(position)
            p = self._connect(x, y)
            w0 = dr.normalize(p - y)
            n = dr.normalize(p - self.centre)
            cos_i = -dr.dot(n, w0)
            visible = cos_i > 1e-6
            F, _, _, _ = mi.fresnel(dr.maximum(cos_i, 1e-6), self.eta)
            d0 = self._refract_in(w0, n)
            frame = mi.Frame3f(w0)
            h = self.delta
            qa1, ha1 = self._beam_point(y, dr.normalize(w0 + h * frame.s), x, d0)
            qa0, ha0 = self._beam_point(y, dr.normalize(w0 - h * frame.s), x, d0)
            qb1, hb1 = self._beam_point(y, dr.normalize(w0 + h * frame.t), x, d0)
            qb0, hb0 = self._beam_point(y, dr.normalize(w0 - h * frame.t), x, d0)
            J = dr.norm(dr.cross(qa1 - qa0, qb1 - qb0)) / (4.0 * h * h)
            # The bisection ends at the edge of the visible cap where x lies outside the
            # region refracted light reaches directly (beyond the grazing rays' envelope):
            # there Snell's law does not hold at p and there is no connection.
            snell = dr.norm(dr.cross(dr.normalize(x - p), d0)) < 1e-3
            ok = visible & snell & ha1 & ha0 & hb1 & hb0 & (J > 0)
            dist = dr.norm(x - p)
            tr = dr.exp(-mi.Spectrum(self.sigma_t) * dist)
            to_light = dr.normalize(p - x)
            phase = self._hg(dr.dot(to_light, d))
            E = mi.Spectrum(intensity) * (1.0 - F) * tr / dr.maximum(J, 1e-30)
            total += dr.select(ok, phase * E, 0.0)
        return total

    @dr.syntax
    def sample(self, scene, sampler, ray, medium=None, active=True):
        env = scene.environment()
        L = mi.Spectrum(0.0)
        o = mi.Point3f(ray.o)
        d = mi.Vector3f(ray.d)
        t0, hit = self._hit_from_outside(o, d)
        active = mi.Bool(active)

        # Misses: the environment as volpath sees it.
        si_env = dr.zeros(mi.SurfaceInteraction3f)
        si_env.wi = -d
        if env is not None:
            L = dr.select(hit, 0.0, env.eval(si_env, active & ~hit))

        p0 = o + t0 * d
        n0 = dr.normalize(p0 - self.centre)
        F0, _, _, _ = mi.fresnel(dr.maximum(-dr.dot(n0, d), 1e-6), self.eta)
        if self.camera_reflection and env is not None:
            si_r = dr.zeros(mi.SurfaceInteraction3f)
            si_r.wi = -(d - 2.0 * dr.dot(d, n0) * n0)
            L += dr.select(hit, F0 * env.eval(si_r, active & hit), 0.0)
        eta2 = self.eta * self.eta
        throughput = mi.Spectrum((1.0 - F0) / eta2)
        d = self._refract_in(d, n0)
        o = p0
        sigma_t = mi.Spectrum(self.sigma_t)
        sigma_s = sigma_t * mi.Spectrum(self.albedo)
        active &= hit
        depth = mi.UInt32(0)

        while active:
            t_exit = self._exit_from_inside(o, d)
            u = sampler.next_1d()
            channel = dr.minimum(mi.UInt32(3.0 * sampler.next_1d()), 2)
            st_c = dr.select(channel == 0, sigma_t[0],
                             dr.select(channel == 1, sigma_t[1], sigma_t[2]))
            t = -dr.log(1.0 - u) / st_c
            scatter = t < t_exit
            t = dr.minimum(t, t_exit)
            tr = dr.exp(-sigma_t * t)
            # Balance heuristic over the three channels' free-flight densities.
            pdf_scatter = dr.mean(sigma_t * tr)
            pdf_escape = dr.mean(tr)
            weight = dr.select(scatter, sigma_s * tr / pdf_scatter, tr / pdf_escape)
            throughput *= weight
            x = o + t * d

            if scatter:
                L += throughput * self._nee(x, d)
                d = self._sample_hg(d, sampler.next_1d(), sampler.next_1d())
                o = x
            else:
                n = dr.normalize(x - self.centre)
                cos_i = dr.dot(n, d)  # > 0: leaving
                F, _, _, _ = mi.fresnel(-cos_i, self.eta)
                reflect = sampler.next_1d() < F
                if reflect:
                    d = d - 2.0 * dr.dot(d, n) * n
                    o = x
                else:
                    # Out: radiance inside = (1 - F) eta^2 L_outside, the (1 - F) by the choice.
                    r = self.eta
                    root = dr.safe_sqrt(1.0 - r * r * (1.0 - cos_i * cos_i))
                    w_out = dr.normalize(r * d + (root - r * cos_i) * n)
                    si_out = dr.zeros(mi.SurfaceInteraction3f)
                    si_out.wi = -w_out
                    if env is not None:
                        L += throughput * eta2 * env.eval(si_out)
                    active = mi.Bool(False)
            depth += 1
            active &= dr.any(throughput > 0.0)
        return L, mi.Bool(True), []


mi.register_integrator("refracted_nee", lambda props: RefractedNee(props))
