"""The contact law as an argument of the compiled loops, bound at compile time.

The engines' loops (:mod:`dem.engines.contact_forces`, :mod:`dem.engines.verlet.loop`,
:mod:`dem.engines.staggered.kernels`) take the law as their first argument, a :class:`ContactLaw`. Its numba type,
a type of its own, carries the law's name and nothing at run time (an empty value): each law is a type of its
own, so numba compiles a loop for each law it is called with, and the law is part of the loop's signature -- the key
of numba's on-disk cache, which therefore never hands one law's loop to another. The loops call the law's kernels
through the functions below (``pair_force(law, ...)``, ``spins(law)``, ...): at compile time each resolves, from the
law's type, to the kernel of the law (:data:`dem.laws.contact.CONTACT_LAWS`), inlined into the loop as if called by
name, so nothing is dispatched at run time and the loop is the same code it would be written against one law. Its
compile-time constants (``spins``, ``has_drag``, ``keeps_pair_constants``) are functions that return a constant,
and the branches they rule out are dropped by the compiler.

The signatures of the law's kernels are those :mod:`dem.laws.contact` lists, with ``law`` in front.
"""

from __future__ import annotations

from numba.core import types
from numba.extending import NativeValue, models, overload, register_model, typeof_impl, unbox
from numba.np.unsafe.ndarray import to_fixed_tuple

from dem.laws.contact import law_module, law_module_name


class ContactLaw:
    """The contact law ``name`` (:data:`dem.laws.contact.CONTACT_LAWS`) as the compiled loops take it.

    Parameters
    ----------
    name : str
        A law of :data:`dem.laws.contact.CONTACT_LAWS`.

    Raises
    ------
    ValueError
        ``name`` is not a known law.
    """

    def __init__(self, name: str):
        law_module_name(name)  # an unknown law is named as such
        self.name = name

    def __repr__(self) -> str:
        return f"ContactLaw({self.name!r})"


class _LawType(types.Dummy):
    """The numba type of a :class:`ContactLaw`: one type per law (its name is the key), no value at run time."""

    def __init__(self, name: str):
        self.law = name
        super().__init__(name=f"ContactLaw({name})")

    @property
    def key(self):
        return self.law


def _typeof(value, context):
    return _LawType(value.name)


typeof_impl.register(ContactLaw)(_typeof)


register_model(_LawType)(models.OpaqueModel)


def _unbox(typ, obj, c):
    return NativeValue(c.context.get_dummy_value())


unbox(_LawType)(_unbox)


def _kernels(law):
    """The module of the law whose type is ``law``, or None for another type (then no overload applies)."""
    return law_module(law.law) if isinstance(law, _LawType) else None


# The stubs the loops call; numba resolves each at compile time (the overloads below). Called from Python they are
# not meant to run: the law's own module is for that.
def pair_force(law, c, i, j, hist_in, hist, state, T, delta, d, n, vr, vn, ri, rj, planar, dt, params, const):
    """The law's ``pair_force`` (:mod:`dem.laws.contact`), in compiled code.

    Parameters
    ----------
    law : ContactLaw
        The contact law, bound at compile time.
    c : int
        The pair's index in the list (its row of the histories).
    i, j : int
        The pair's particles.
    hist_in, hist : numpy.ndarray
        The contacts' histories read and written (the law's ``PAIR_HISTORY`` or ``WALL_HISTORY`` columns).
    state : numpy.ndarray
        (N, S) the particles' state (the law's ``PARTICLE_STATE``).
    T : numpy.ndarray
        (N,) temperatures (the law's unit).
    delta : float
        The overlap (m), positive in contact.
    d : float
        The distance of the centres (m).
    n : tuple of float
        The unit normal, from j (or the wall) to i.
    vr, vn : tuple of float, float
        The relative surface velocity (m/s) and its normal part.
    ri, rj : float
        The radii (m).
    planar : bool
        2D disks in the x-z plane.
    dt : float
        The time step (s).
    params : tuple or numpy.ndarray
        The law's material (its ``params()``).
    const : tuple of float
        The pair's numbers of its radii alone (the law's ``pair_constants``).
    """


def pair_constants(law, ri, rj, params):
    """The law's ``pair_constants``, in compiled code.

    Parameters
    ----------
    law : ContactLaw
        The contact law, bound at compile time.
    ri, rj : float
        The radii (m).
    params : tuple or numpy.ndarray
        The law's material (its ``params()``).
    """


def forget_pair(law, c, hist_in, hist):
    """The law's ``forget_pair``, in compiled code.

    Parameters
    ----------
    law : ContactLaw
        The contact law, bound at compile time.
    c : int
        The pair's index in the list (its row of the histories).
    hist_in, hist : numpy.ndarray
        The contacts' histories read and written (the law's ``PAIR_HISTORY`` or ``WALL_HISTORY`` columns).
    """


def reach(law, c, hist, ri, rj, params):
    """The law's ``reach``, in compiled code.

    Parameters
    ----------
    law : ContactLaw
        The contact law, bound at compile time.
    c : int
        The pair's index in the list (its row of the histories).
    hist : numpy.ndarray
        The contacts' histories (the law's columns).
    ri, rj : float
        The radii (m).
    params : tuple or numpy.ndarray
        The law's material (its ``params()``).
    """


def wall_force(law, k, m, hist_in, hist, state, T, delta, dist, n, vr, vn, rk, dt, params):
    """The law's ``wall_force``, in compiled code.

    Parameters
    ----------
    law : ContactLaw
        The contact law, bound at compile time.
    k, m : int
        The particle and the wall.
    hist_in, hist : numpy.ndarray
        The contacts' histories read and written (the law's ``PAIR_HISTORY`` or ``WALL_HISTORY`` columns).
    state : numpy.ndarray
        (N, S) the particles' state (the law's ``PARTICLE_STATE``).
    T : numpy.ndarray
        (N,) temperatures (the law's unit).
    delta : float
        The overlap (m), positive in contact.
    dist : float
        The distance of the particle's centre from the wall (m).
    n : tuple of float
        The unit normal, from j (or the wall) to i.
    vr, vn : tuple of float, float
        The relative surface velocity (m/s) and its normal part.
    rk : float
        The particle's radius (m).
    dt : float
        The time step (s).
    params : tuple or numpy.ndarray
        The law's material (its ``params()``).
    """


def forget_wall(law, k, m, hist_in, hist):
    """The law's ``forget_wall``, in compiled code.

    Parameters
    ----------
    law : ContactLaw
        The contact law, bound at compile time.
    k, m : int
        The particle and the wall.
    hist_in, hist : numpy.ndarray
        The contacts' histories read and written (the law's ``PAIR_HISTORY`` or ``WALL_HISTORY`` columns).
    """


def wall_reach(law, k, m, hist, rk, params):
    """The law's ``wall_reach``, in compiled code.

    Parameters
    ----------
    law : ContactLaw
        The contact law, bound at compile time.
    k, m : int
        The particle and the wall.
    hist : numpy.ndarray
        The contacts' histories (the law's columns).
    rk : float
        The particle's radius (m).
    params : tuple or numpy.ndarray
        The law's material (its ``params()``).
    """


def drag(law, k, radius, params):
    """The law's ``drag``, in compiled code.

    Parameters
    ----------
    law : ContactLaw
        The contact law, bound at compile time.
    k : int
        The particle.
    radius : numpy.ndarray
        (N,) radii (m).
    params : tuple or numpy.ndarray
        The law's material (its ``params()``).
    """


def update_particles(law, elapsed, T0, T_rate, T, radius, radius_ref, state, uniform, params, t0, dt):
    """The law's ``update_particles``, in compiled code.

    Parameters
    ----------
    law : ContactLaw
        The contact law, bound at compile time.
    elapsed, t0 : float
        The time since the interval began and the relaxation time (s).
    T0, T_rate : numpy.ndarray
        The temperatures at the interval's start and their rates (K/s).
    T, radius, radius_ref, state : numpy.ndarray
        The temperatures, radii, reference radii and state, updated in place.
    uniform : bool
        One temperature for all.
    params : tuple or numpy.ndarray
        The law's material (its ``params()``).
    dt : float
        The time step (s).
    """


def spins(law):
    """The law's ``SPINS`` (its tangential forces make torques), a compile-time constant.

    Parameters
    ----------
    law : ContactLaw
        The contact law, bound at compile time.
    """


def has_drag(law):
    """The law's ``DRAG`` (it has a drag on every particle), a compile-time constant.

    Parameters
    ----------
    law : ContactLaw
        The contact law, bound at compile time.
    """


def keeps_pair_constants(law):
    """Whether the law keeps numbers of the radii per pair (its ``PAIR_CONSTANTS`` are not empty), a compile-time
    constant.

    Parameters
    ----------
    law : ContactLaw
        The contact law, bound at compile time.
    """


def params_tuple(law, params):
    """The law's parameter array as a tuple of its ``N_PARAMS`` numbers (the loops pass the material as a tuple: an
    array passed to an inlined kernel costs an atomic reference count per call).

    Parameters
    ----------
    law : ContactLaw
        The contact law, bound at compile time.
    params : tuple or numpy.ndarray
        The law's material (its ``params()``).
    """


def _pair_force(law, c, i, j, hist_in, hist, state, T, delta, d, n, vr, vn, ri, rj, planar, dt, params, const):
    module = _kernels(law)
    if module is not None:
        kernel = module.pair_force

        def impl(law, c, i, j, hist_in, hist, state, T, delta, d, n, vr, vn, ri, rj, planar, dt, params, const):
            return kernel(c, i, j, hist_in, hist, state, T, delta, d, n, vr, vn, ri, rj, planar, dt, params, const)
        return impl


overload(pair_force, inline="always")(_pair_force)


def _pair_constants(law, ri, rj, params):
    module = _kernels(law)
    if module is not None:
        kernel = module.pair_constants

        def impl(law, ri, rj, params):
            return kernel(ri, rj, params)
        return impl


overload(pair_constants, inline="always")(_pair_constants)


def _forget_pair(law, c, hist_in, hist):
    module = _kernels(law)
    if module is not None:
        kernel = module.forget_pair

        def impl(law, c, hist_in, hist):
            return kernel(c, hist_in, hist)
        return impl


overload(forget_pair, inline="always")(_forget_pair)


def _reach(law, c, hist, ri, rj, params):
    module = _kernels(law)
    if module is not None:
        kernel = module.reach

        def impl(law, c, hist, ri, rj, params):
            return kernel(c, hist, ri, rj, params)
        return impl


overload(reach, inline="always")(_reach)


def _wall_force(law, k, m, hist_in, hist, state, T, delta, dist, n, vr, vn, rk, dt, params):
    module = _kernels(law)
    if module is not None:
        kernel = module.wall_force

        def impl(law, k, m, hist_in, hist, state, T, delta, dist, n, vr, vn, rk, dt, params):
            return kernel(k, m, hist_in, hist, state, T, delta, dist, n, vr, vn, rk, dt, params)
        return impl


overload(wall_force, inline="always")(_wall_force)


def _forget_wall(law, k, m, hist_in, hist):
    module = _kernels(law)
    if module is not None:
        kernel = module.forget_wall

        def impl(law, k, m, hist_in, hist):
            return kernel(k, m, hist_in, hist)
        return impl


overload(forget_wall, inline="always")(_forget_wall)


def _wall_reach(law, k, m, hist, rk, params):
    module = _kernels(law)
    if module is not None:
        kernel = module.wall_reach

        def impl(law, k, m, hist, rk, params):
            return kernel(k, m, hist, rk, params)
        return impl


overload(wall_reach, inline="always")(_wall_reach)


def _drag(law, k, radius, params):
    module = _kernels(law)
    if module is not None:
        kernel = module.drag

        def impl(law, k, radius, params):
            return kernel(k, radius, params)
        return impl


overload(drag, inline="always")(_drag)


def _update_particles(law, elapsed, T0, T_rate, T, radius, radius_ref, state, uniform, params, t0, dt):
    module = _kernels(law)
    if module is not None:
        kernel = module.update_particles  # compiled on its own (not inlined), as when called by name

        def impl(law, elapsed, T0, T_rate, T, radius, radius_ref, state, uniform, params, t0, dt):
            return kernel(elapsed, T0, T_rate, T, radius, radius_ref, state, uniform, params, t0, dt)
        return impl


overload(update_particles, inline="always")(_update_particles)


def _constant(value):
    def impl(law):
        return value
    return impl


def _spins(law):
    module = _kernels(law)
    if module is not None:
        return _constant(bool(module.SPINS))


overload(spins, inline="always")(_spins)


def _has_drag(law):
    module = _kernels(law)
    if module is not None:
        return _constant(bool(module.DRAG))


overload(has_drag, inline="always")(_has_drag)


def _keeps_pair_constants(law):
    module = _kernels(law)
    if module is not None:
        return _constant(len(module.PAIR_CONSTANTS) > 0)


overload(keeps_pair_constants, inline="always")(_keeps_pair_constants)


def _params_tuple(law, params):
    module = _kernels(law)
    if module is not None:
        size = module.N_PARAMS

        def impl(law, params):
            return to_fixed_tuple(params, size)
        return impl


overload(params_tuple, inline="always")(_params_tuple)
