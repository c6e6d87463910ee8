"""Files that look wrong are flagged: positions printed with 6 significant digits where contacts sit within that
rounding, radii that suggest another length unit, a LAMMPS data file in micro units without its units line, an id
given to two atoms (blamed on the Atoms section, not on the Velocities that follow)."""

import warnings

import numpy as np
import pytest

from dem import read_packing
from dem.scene import parse_scene
from dem.scene.packing_files import printed_precision

R = 5e-5  # m


def chain_csv(path, xs, radius=R):
    path.write_text("x,y,z,radius\n" + "".join(f"{x},0,0,{radius}\n" for x in xs))
    return path


def quiet(path, **options):
    """read_packing, failing on any warning."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        return read_packing(path, **options)


def test_printed_precision():
    assert printed_precision(np.array([0.0, 1.23457e-4, -9.87654e-3])) == pytest.approx(0.5e-8)
    assert printed_precision(np.array([1.234567e-4])) is None  # 7 digits
    assert printed_precision(np.array([1.0 / 3.0])) is None


def test_six_digits_with_contacts_within_them_are_flagged(tmp_path):
    """Particles 0 and 1 touch (gap 0, within the rounding); 1 and 2 overlap by 1 um, far beyond it; 2 and 3 are
    apart. The same centres with a seventh digit are not flagged, nor are 6 digits with no contact near touching."""
    xs = ["0", "0.0001", "0.000199", "0.000400"]
    with pytest.warns(UserWarning, match=r"6 significant digits \(rounded by up to 5e-10 m\) and 1 pair\(s\) within "
                                         r"1\.73e-09 m of touching \(1 contacts in all\)"):
        read_packing(chain_csv(tmp_path / "six.csv", xs))
    quiet(chain_csv(tmp_path / "seven.csv", ["0", "0.0001000001", "0.000199", "0.000400"]))
    quiet(chain_csv(tmp_path / "apart.csv", ["0", "0.000099", "0.000197", "0.000400"]))


@pytest.mark.parametrize("radius, length_unit, message", [
    (50.0, 1.0, r"median radius is 50 m \(read with length_unit = 1\): .* is the file in mm \(length_unit = 1e-3\) "
                r"or um \(1e-6\)\?"),
    (5e-5, 1e-6, r"median radius is 5e-11 m \(read with length_unit = 1e-06\): .* is the file in metres read with a "
                 r"length_unit for mm or um\?"),
])
def test_radii_in_another_unit_are_flagged(tmp_path, radius, length_unit, message):
    with pytest.warns(UserWarning, match=message):
        read_packing(chain_csv(tmp_path / "p.csv", [0.0, 10 * radius], radius), length_unit=length_unit)
    quiet(chain_csv(tmp_path / "q.csv", [0.0, 10 * R]))


DATA = ("LAMMPS data file via write_data{units}\n\n2 atoms\n1 atom types\n\n0 2000 xlo xhi\n0 2000 ylo yhi\n"
        "0 2000 zlo zhi\n\nAtoms # sphere\n\n1 1 100 8.96 500 500 500\n2 1 100 8.96 590 500 500\n")


def test_a_micro_data_file_without_its_units_line(tmp_path):
    """100 um spheres of copper (8.96 pg/um^3) in units micro: read right with the title's units; without it the
    radii are flagged and a scene says what the densities are."""
    (tmp_path / "um.data").write_text(DATA.format(units=", units = micro"))
    p = quiet(tmp_path / "um.data")
    np.testing.assert_allclose(p.radius, 5e-5, rtol=1e-15)
    np.testing.assert_allclose(p.density, 8960.0, rtol=1e-15)
    (tmp_path / "bare.data").write_text(DATA.format(units=""))
    with pytest.warns(UserWarning, match=r"median radius is 50 m \(read with length_unit = 1 and no LAMMPS units "
                                         r"line\)"):
        read_packing(tmp_path / "bare.data")
    doc = {"material": {"conductivity": 394.0, "density": 8960.0, "specific_heat": 385.0},
           "particles": {"file": str(tmp_path / "bare.data"), "temperature": 0.0}}
    with pytest.warns(UserWarning), pytest.raises(ValueError, match=r"has density 8\.96 kg/m\^3 but its material "
                                                                    r"'material0' 8960; 8\.96 is the material's "
                                                                    r"density in g/cm\^3, .*`units = micro`"):
        parse_scene(doc)


def test_an_id_given_twice_is_blamed_on_the_atoms(tmp_path):
    (tmp_path / "dup.data").write_text(
        "LAMMPS data file\n\n2 atoms\n1 atom types\n\n0 1 xlo xhi\n0 1 ylo yhi\n0 1 zlo zhi\n\nAtoms # sphere\n\n"
        "1 1 0.1 1000 0.5 0.5 0.5\n1 1 0.1 1000 0.5 0.5 0.6\n\nVelocities\n\n1 0 0 0 0 0 0\n1 0 0 0 0 0 0\n")
    with pytest.raises(ValueError, match=r"dup\.data, line 13: id 1 is given to two atoms \(lines 12 and 13\); ids "
                                         r"must be unique"):
        read_packing(tmp_path / "dup.data")
