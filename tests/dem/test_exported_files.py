"""The files of the codes that are not run here (MercuryDPM, MFiX) hold only names and
values their sources and documentation accept (a read check, see docs/dem.md)."""

import re

import numpy as np
import pytest

#: MercuryDPM: the species class (Kernel/Species/HertzianBSHPViscoelasticMindlinSpecies.h) and
#: the setters of its parts (HertzianViscoelasticNormalSpecies, MindlinSpecies, ParticleSpecies;
#: MindlinSpecies::setSlidingDissipation is read by MindlinInteraction::computeFrictionForce)
MERCURY_SETTERS = {"setDensity", "setEffectiveElasticModulus", "setDissipation",
                   "setEffectiveShearModulus", "setSlidingDissipation",
                   "setSlidingFrictionCoefficient"}
#: MFiX LSD keywords (DES_ETAT_FAC, DES_ETAT_W_FAC in [0, 1]; KT_FAC, KT_W_FAC, not DES_KT_*)
MFIX_KEYS = {"DES_COLL_MODEL", "DES_EN_INPUT", "DES_EN_WALL_INPUT", "KN", "KN_W", "KT_FAC",
             "KT_W_FAC", "DES_ETAT_FAC", "DES_ETAT_W_FAC", "MEW", "MEW_W"}


@pytest.fixture(scope="module")
def mfix_export(code_run):
    """The MFiX export of ``WIRING`` and its folder: ``vimpact dem --for mfix``'s run
    of the CLI test, for the checks of its file and of its fit."""
    run = code_run("mfix")
    assert run.status == 0
    return run.export, run.folder


def test_mercurydpm_species_compiles_by_name(code_run):
    """The species file ``vimpact dem --for mercurydpm`` wrote for ``WIRING`` (the same
    run as the CLI test's)."""
    run = code_run("mercurydpm")
    assert run.status == 0
    text = (run.folder / "mercurydpm_species.cpp").read_text()
    assert '#include "Species/HertzianBSHPViscoelasticMindlinSpecies.h"' in text
    assert "HertzianBSHPViscoelasticSlidingFrictionSpecies" not in text
    code = "\n".join(ln.split("//")[0] for ln in text.splitlines())
    assert set(re.findall(r"->(set\w+)\(", code)) == MERCURY_SETTERS
    # friction comes with a tangential stiffness and dissipation wherever it is set
    assert text.count("setSlidingFrictionCoefficient") == text.count("setEffectiveShearModulus")
    assert text.count("setSlidingDissipation") == text.count("setEffectiveShearModulus")


def test_mfix_keywords_and_ranges(mfix_export):
    ex, out = mfix_export
    lines = [ln.split("!")[0] for ln in (out / "mfix.dat").read_text().splitlines()]
    values = dict(ln.split("=", 1) for ln in lines if "=" in ln)
    values = {k.strip(): v.strip() for k, v in values.items()}
    assert set(values) <= MFIX_KEYS
    for key in ("DES_ETAT_FAC", "DES_ETAT_W_FAC"):
        assert 0.0 <= float(values[key]) <= 1.0
    # the reported beta_x residual is that of the value written
    for f in ex.fits:
        assert 0.0 <= f.params["etat_fac"] <= 1.0 and f.res_beta_x is not None


def test_mfix_tangential_factor_is_fitted_with_the_friction(mfix_export):
    """With friction, the reported beta_x residual of MFiX is over the oblique impacts,
    MFiX's law run with the MEW written (one value)."""
    ex, _ = mfix_export
    for f in ex.fits:
        ob = ex.targets[f.contact.key].oblique
        assert f.beta_oblique is not None and f.beta_oblique.shape == ob.beta_x.shape
        assert f.res_beta_x.max_abs == pytest.approx(np.max(np.abs(f.beta_oblique - ob.beta_x)))
