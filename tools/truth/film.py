"""`truth_film`: a pigment film at a medium's surface, as a Mitsuba BSDF written in Python.

An index-matched interface (like `null`: a ray passes straight through, the medium changes)
whose transmittance is per channel, from a texture: A(uv)^a_out for light leaving the object
(crossing against the outward normal's side... i.e. the light travels to the outside) and
A(uv)^a_in for light entering it. With a_in = a_out = 1/2 it is a thin absorbing film of
transmittance sqrt(A), crossed on the way in and on the way out (light that enters at one
point and leaves at another is filtered by sqrt(A_in) sqrt(A_out): lucent's `pre-post`);
(0, 1) is lucent's `post`, (1, 0) its `pre` (lucent_to_mitsuba.py FILM_EXPONENTS).

Mitsuba's `volpath` crosses it as it crosses `null`: camera paths sample it (the only
component is `Null`: direction unchanged, weight the transmittance, the ray's medium updated at
the medium transition), and shadow rays multiply `eval_null_transmission` along the way. Which
way light travels: along `si.wi` (towards where the path came from), so light leaves the
object where `si.wi` is on the outside of the surface (cos_theta(si.wi) > 0: the sphere's
normals point outward).
"""

from __future__ import annotations

import drjit as dr
import mitsuba as mi


class TruthFilm(mi.BSDF):
    def __init__(self, props):
        mi.BSDF.__init__(self, props)
        self.albedo = props["albedo"]
        self.a_in = float(props.get("a_in", 0.5))
        self.a_out = float(props.get("a_out", 0.5))
        flags = mi.BSDFFlags.Null | mi.BSDFFlags.FrontSide | mi.BSDFFlags.BackSide
        self.m_components = [flags]
        self.m_flags = flags

    def _transmittance(self, si, active):
        a = dr.maximum(self.albedo.eval(si, active), 0.0)
        leaving = mi.Frame3f.cos_theta(si.wi) > 0
        exponent = dr.select(leaving, self.a_out, self.a_in)
        # A^0 = 1 also where A = 0.
        return dr.select(exponent == 0.0, 1.0, dr.power(a, exponent))

    def sample(self, ctx, si, sample1, sample2, active=True):
        bs = dr.zeros(mi.BSDFSample3f)
        bs.wo = -si.wi
        bs.pdf = mi.Float(1.0)
        bs.eta = mi.Float(1.0)
        bs.sampled_type = mi.UInt32(+mi.BSDFFlags.Null)
        bs.sampled_component = mi.UInt32(0)
        return bs, self._transmittance(si, active)

    def eval(self, ctx, si, wo, active=True):
        return mi.Spectrum(0.0)

    def pdf(self, ctx, si, wo, active=True):
        return mi.Float(0.0)

    def eval_pdf(self, ctx, si, wo, active=True):
        return mi.Spectrum(0.0), mi.Float(0.0)

    def eval_null_transmission(self, si, active=True):
        return self._transmittance(si, active)

    def traverse(self, callback):
        pass

    def to_string(self):
        return f"TruthFilm[a_in={self.a_in}, a_out={self.a_out}]"


mi.register_bsdf("truth_film", lambda props: TruthFilm(props))
