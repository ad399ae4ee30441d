"""Materials say what they are: their repr shows the parameters they were made with."""
import pytest

import snede


def test_materials_show_their_parameters():
    assert repr(snede.NeoHookean(34e3, 0.34)) == "NeoHookean(E=34000.0, nu=0.34)"
    veronda = snede.VerondaWestmann(3e3, 0.3, 8.0)
    assert repr(veronda).startswith("VerondaWestmann(E=3000.0") and "gamma=8.0" in repr(veronda)
    assert veronda.E == pytest.approx(3e3) and veronda.nu == pytest.approx(0.3)
    with pytest.raises(ValueError, match="needs gamma"):
        snede.VerondaWestmann(3e3, 0.3)
    with pytest.raises(ValueError, match="needs nu, Poisson's ratio, and gamma"):
        snede.VerondaWestmann(3e3)
    # E and ν come back from the Lamé parameters; the repr does not show their round-off.
    assert repr(snede.LinearElastic(1e3, 0.3)) == "LinearElastic(E=1000.0, nu=0.3)"
    assert repr(snede.StVenantKirchhoff(2.5e-3, 0.1)) == "StVenantKirchhoff(E=0.0025, nu=0.1)"
    assert repr(snede.VerondaWestmann(3e3, 0.3, 8.0)) == "VerondaWestmann(E=3000.0, nu=0.3, gamma=8.0)"
