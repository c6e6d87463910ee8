"""The contact law as an argument of the compiled loops, put together from its sub-models at compile time.

The engines' loops (:mod:`dem.engines.contact_forces`, :mod:`dem.engines.verlet.loop`,
:mod:`dem.engines.staggered.kernels`) take the law as their first argument, a :class:`ContactLaw`. Its numba type,
a type of its own, carries the law's name and its composition (:class:`dem.laws.contact.composition.Composition`)
and nothing at run time (an empty value): each composition is a type of its own, so numba compiles a loop for each
law it is called with, and the composition is part of the loop's signature -- the key of numba's on-disk cache,
which therefore never hands one composition's loop to another (also where a law's line changed but its name did
not). The loops call the law through the functions below (``pair_force(law, ...)``, ``spins(law)``, ...): at compile
time each resolves, from the law's type, to the sub-models' kernels called one after the other (normal, adhesion,
damping, tangential: :mod:`dem.laws.contact.composition`), inlined into the loop, so nothing is dispatched at run
time and the loop is the same code it would be written against one law. Its compile-time constants (``spins``,
``has_drag``, ``keeps_pair_constants``) are functions that return a constant, and the branches they rule out are
dropped by the compiler.

A contact is passed as one tuple, ``contact``, of ``(delta, d, n, vr, vn)``: the overlap (m, positive in contact), the
distance of the centres (of the particle's centre from the wall), the unit normal from j (the wall) to i, the
relative surface velocity (m/s) and its normal part. The parameters are the law's blocks
(:meth:`dem.laws.contact.composition.Law.params`), as a tuple of tuples in the force loop (:func:`params_tuple`).
"""

from __future__ import annotations

from numba import njit
from numba.core import types
from numba.extending import NativeValue, models, overload, register_model, typeof_impl, unbox
from numba.np.unsafe.ndarray import to_fixed_tuple

from dem.laws.contact import composition_of
from dem.laws.contact.composition import Law
from dem.laws.contact.kernel_options import IN_LOOP


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
        self.composition = composition_of(name)  # an unknown law is named as such
        self.name = name

    def __repr__(self) -> str:
        return f"ContactLaw({self.name!r})"


class _LawType(types.Dummy):
    """The numba type of a :class:`ContactLaw`: one type per law and composition (the key), no value at run
    time."""

    def __init__(self, name: str, composition):
        self.law = name
        self.composition = composition
        super().__init__(name=f"ContactLaw({name}: {composition})")

    @property
    def key(self):
        return self.law, self.composition


def _typeof(value, context):
    return _LawType(value.name, value.composition)


typeof_impl.register(ContactLaw)(_typeof)


register_model(_LawType)(models.OpaqueModel)


def _unbox(typ, obj, c):
    return NativeValue(c.context.get_dummy_value())


unbox(_LawType)(_unbox)


_LAWS = {}  # the laws put together, by their types' keys


def _law(law):
    """The law whose type is ``law``, put together, or None for another type (then no overload applies)."""
    if not isinstance(law, _LawType):
        return None
    if law.key not in _LAWS:
        _LAWS[law.key] = Law(law.law, law.composition)
    return _LAWS[law.key]


# The stubs the loops call; numba resolves each at compile time (the overloads below). Called from Python they are
# not meant to run: the law's own module is for that.
def pair_force(law, c, i, j, hist_in, hist, state, T, contact, ri, rj, planar, dt, params, const):
    """The force on particle i of the closed pair ``c`` = (i, j), ``(f_n, f_t0, f_t1, f_t2)``: the law's sub-models
    one after the other (:mod:`dem.laws.contact.composition`), in compiled code.

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
    contact : tuple
        ``(delta, d, n, vr, vn)``: the overlap (m), the distance of the centres (m), the unit normal from j to i (a
        3-tuple), the relative surface velocity (m/s, a 3-tuple) and its normal part (m/s).
    ri, rj : float
        The radii (m).
    planar : bool
        2D disks in the x-z plane.
    dt : float
        The time step (s).
    params : tuple
        The law's parameter blocks (:func:`params_tuple`).
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
    params : tuple
        The law's parameter blocks (:func:`params_tuple`).
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
    params : tuple
        The law's parameter blocks (:func:`params_tuple`).
    """


def wall_force(law, k, m, hist_in, hist, state, T, contact, rk, dt, params):
    """The force on particle k from wall m, ``(f_n, f_t0, f_t1, f_t2)``: the law's sub-models one after the other,
    in compiled code.

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
    contact : tuple
        ``(delta, dist, n, vr, vn)``: the overlap (m), the distance of the particle's centre from the wall (m), the
        wall's unit normal (towards the particle, a 3-tuple), the relative surface velocity (m/s, a 3-tuple) and its
        normal part (m/s).
    rk : float
        The particle's radius (m).
    dt : float
        The time step (s).
    params : tuple
        The law's parameter blocks (:func:`params_tuple`).
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
    params : tuple
        The law's parameter blocks (:func:`params_tuple`).
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
    params : tuple
        The law's parameter blocks (:func:`params_tuple`).
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
    params : numpy.ndarray
        The law's parameters (:meth:`dem.laws.contact.composition.Law.params`).
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
    """The law's parameter array as a tuple of its blocks, each a tuple of its numbers (the loops pass the material
    as tuples: an array passed to an inlined kernel costs an atomic reference count per call).

    Parameters
    ----------
    law : ContactLaw
        The contact law, bound at compile time.
    params : numpy.ndarray
        The law's parameters (:meth:`dem.laws.contact.composition.Law.params`).
    """


# ------------------------------------------------------------------------------------------ the overloads
@njit(**IN_LOOP)
def _undamped_pair(state, i, j, f_el, delta_dot, k_n, params):
    return f_el, 0.0


@njit(**IN_LOOP)
def _undamped_wall(state, k, f_el, delta_dot, k_n, params):
    return f_el, 0.0


def _parts(law):
    """What the overloads take of the law whose type is ``law``: its modules, their blocks' indices and the first
    history columns of each slot (pairs, walls)."""
    spec = _law(law)
    blocks = {slot: spec.block(slot) for slot, module in spec.modules.items()
              if module is not None and module.PARAMS is not None}
    return spec, blocks, spec.columns


def _pair_force(law, c, i, j, hist_in, hist, state, T, contact, ri, rj, planar, dt, params, const):
    if _law(law) is None:
        return None
    spec, blocks, columns = _parts(law)
    normal, tangential, adhesion = spec.modules["normal"], spec.modules["tangential"], spec.modules["adhesion"]
    damping = spec.modules["damping"]
    normal_force, tangential_force = normal.pair, tangential.pair
    damped = _undamped_pair if damping is None else damping.pair
    bn, bt = blocks["normal"], blocks["tangential"]
    bd = blocks.get("damping", bn)
    cn, ct = columns["normal"][0], columns["tangential"][0]
    if adhesion is None:
        def impl(law, c, i, j, hist_in, hist, state, T, contact, ri, rj, planar, dt, params, const):
            at = (c,)
            f_el, k_n, a, f_min, soft, r_eff = normal_force(at, cn, hist_in, hist, state, T, i, j, contact, ri, rj,
                                                            params[bn], const)
            f_n, eta = damped(state, i, j, f_el, -contact[4], k_n, params[bd])
            return tangential_force(at, ct, hist_in, hist, contact, planar, f_n, f_n - f_min, k_n, a, eta, soft, dt,
                                    params[bt])
        return impl
    adhesive = adhesion.pair
    ba, ca = blocks["adhesion"], columns["adhesion"][0]

    def impl(law, c, i, j, hist_in, hist, state, T, contact, ri, rj, planar, dt, params, const):
        at = (c,)
        f_el, k_n, a, f_min, soft, r_eff = normal_force(at, cn, hist_in, hist, state, T, i, j, contact, ri, rj,
                                                        params[bn], const)
        f_el, k_n, a, load = adhesive(at, ca, hist_in, hist, contact, f_el, k_n, a, r_eff, ri, rj, params[ba])
        f_n, eta = damped(state, i, j, f_el, -contact[4], k_n, params[bd])
        return tangential_force(at, ct, hist_in, hist, contact, planar, f_n, load, k_n, a, eta, soft, dt, params[bt])
    return impl


overload(pair_force, inline="always")(_pair_force)


def _wall_force(law, k, m, hist_in, hist, state, T, contact, rk, dt, params):
    if _law(law) is None:
        return None
    spec, blocks, columns = _parts(law)
    normal, tangential, adhesion = spec.modules["normal"], spec.modules["tangential"], spec.modules["adhesion"]
    damping = spec.modules["damping"]
    normal_force, tangential_force = normal.wall, tangential.wall
    damped = _undamped_wall if damping is None else damping.wall
    bn, bt = blocks["normal"], blocks["tangential"]
    bd = blocks.get("damping", bn)
    cn, ct = columns["normal"][1], columns["tangential"][1]
    if adhesion is None:
        def impl(law, k, m, hist_in, hist, state, T, contact, rk, dt, params):
            at = (k, m)
            f_el, k_n, a, f_min, soft, r_eff = normal_force(at, cn, hist_in, hist, state, T, k, contact, rk,
                                                            params[bn])
            f_n, eta = damped(state, k, f_el, -contact[4], k_n, params[bd])
            return tangential_force(at, ct, hist_in, hist, contact, f_n, f_n - f_min, k_n, a, eta, soft, dt,
                                    params[bt])
        return impl
    adhesive = adhesion.wall
    ba, ca = blocks["adhesion"], columns["adhesion"][1]

    def impl(law, k, m, hist_in, hist, state, T, contact, rk, dt, params):
        at = (k, m)
        f_el, k_n, a, f_min, soft, r_eff = normal_force(at, cn, hist_in, hist, state, T, k, contact, rk, params[bn])
        f_el, k_n, a, load = adhesive(at, ca, hist_in, hist, contact, f_el, k_n, a, rk, params[ba])
        f_n, eta = damped(state, k, f_el, -contact[4], k_n, params[bd])
        return tangential_force(at, ct, hist_in, hist, contact, f_n, load, k_n, a, eta, soft, dt, params[bt])
    return impl


overload(wall_force, inline="always")(_wall_force)


def _forgetting(law, wall: bool):
    """The ``forget`` kernels of the slots with a history of the contact's kind, with their first columns, and,
    where the first is a normal sub-model whose history guards the others (``GUARDS``), the first column after the
    normal's and the number of the others' columns (else None)."""
    spec, blocks, columns = _parts(law)
    found, slots = [], []
    for slot, (pair_column, wall_column) in columns.items():
        module = spec.modules[slot]
        if module.WALL_HISTORY if wall else module.PAIR_HISTORY:
            found.append((module.forget, wall_column if wall else pair_column))
            slots.append(slot)
    normal = spec.modules["normal"]
    if slots[:1] != ["normal"] or not getattr(normal, "GUARDS", False):
        return found, None
    width = len(spec.WALL_HISTORY if wall else spec.PAIR_HISTORY)
    start = found[0][1] + len(normal.WALL_HISTORY if wall else normal.PAIR_HISTORY)
    return found, (start, width - start)


def _zeroing(clear, column):
    """``clear(at, hist)`` and then column ``column`` of row ``at`` zeroed (a constant index: one store, as written
    out by hand; a loop over the columns is slower)."""
    def then(at, hist):
        clear(at, hist)
        hist[at + (column,)] = 0.0
    return njit(inline="always")(then)


@njit(inline="always")
def _nothing(at, hist):
    pass


def _forget(found, guarded):
    """``forget(at, hist_in, hist)``: every slot's ``forget`` called, whether any had a history. Under a guarding
    normal sub-model (``guarded = (start, count)``) only its own: a contact without its history has no other, and
    one with it has the ``count`` columns from ``start`` (the other slots') zeroed, which is their ``forget``
    (:mod:`dem.laws.contact.composition`), without reading them first."""
    if guarded is not None:
        (f0, c0), (start, count) = found[0], guarded
        clear = _nothing
        for column in range(start, start + count):
            clear = _zeroing(clear, column)

        def forget(at, hist_in, hist):
            if not f0(at, c0, hist_in, hist):
                return False
            clear(at, hist)
            return True
    elif not found:
        def forget(at, hist_in, hist):
            return False
    elif len(found) == 1:
        (f0, c0), = found

        def forget(at, hist_in, hist):
            return f0(at, c0, hist_in, hist)
    elif len(found) == 2:
        (f0, c0), (f1, c1) = found

        def forget(at, hist_in, hist):
            h0 = f0(at, c0, hist_in, hist)
            h1 = f1(at, c1, hist_in, hist)
            return h0 or h1
    else:
        (f0, c0), (f1, c1), (f2, c2) = found

        def forget(at, hist_in, hist):
            h0 = f0(at, c0, hist_in, hist)
            h1 = f1(at, c1, hist_in, hist)
            h2 = f2(at, c2, hist_in, hist)
            return h0 or h1 or h2
    return njit(inline="always")(forget)


def _forget_pair(law, c, hist_in, hist):
    if _law(law) is None:
        return None
    forget = _forget(*_forgetting(law, False))

    def impl(law, c, hist_in, hist):
        return forget((c,), hist_in, hist)
    return impl


overload(forget_pair, inline="always")(_forget_pair)


def _forget_wall(law, k, m, hist_in, hist):
    if _law(law) is None:
        return None
    forget = _forget(*_forgetting(law, True))

    def impl(law, k, m, hist_in, hist):
        return forget((k, m), hist_in, hist)
    return impl


overload(forget_wall, inline="always")(_forget_wall)


def _reach(law, c, hist, ri, rj, params):
    if _law(law) is None:
        return None
    spec, blocks, columns = _parts(law)
    if spec.modules["adhesion"] is None:
        def impl(law, c, hist, ri, rj, params):
            return 0.0
        return impl
    kernel, column = spec.modules["adhesion"].reach, columns["adhesion"][0]

    def impl(law, c, hist, ri, rj, params):
        return kernel((c,), column, hist)
    return impl


overload(reach, inline="always")(_reach)


def _wall_reach(law, k, m, hist, rk, params):
    if _law(law) is None:
        return None
    spec, blocks, columns = _parts(law)
    if spec.modules["adhesion"] is None:
        def impl(law, k, m, hist, rk, params):
            return 0.0
        return impl
    kernel, column = spec.modules["adhesion"].reach, columns["adhesion"][1]

    def impl(law, k, m, hist, rk, params):
        return kernel((k, m), column, hist)
    return impl


overload(wall_reach, inline="always")(_wall_reach)


def _pair_constants(law, ri, rj, params):
    if _law(law) is None:
        return None
    spec, blocks, columns = _parts(law)
    kernel, bn = spec.modules["normal"].pair_constants, blocks["normal"]

    def impl(law, ri, rj, params):
        return kernel(ri, rj, params[bn])
    return impl


overload(pair_constants, inline="always")(_pair_constants)


def _drag(law, k, radius, params):
    if _law(law) is None:
        return None
    spec, blocks, columns = _parts(law)
    if spec.modules["drag"] is None:
        def impl(law, k, radius, params):
            return 0.0
        return impl
    kernel, b = spec.modules["drag"].drag, blocks["drag"]

    def impl(law, k, radius, params):
        return kernel(k, radius, params[b])
    return impl


overload(drag, inline="always")(_drag)


def _bounds(spec):
    """The (start, stop) of each parameter block in the law's array."""
    out, start = [], 0
    for pack, size in spec.blocks:
        out.append((start, start + size))
        start += size
    return out


def _update_particles(law, elapsed, T0, T_rate, T, radius, radius_ref, state, uniform, params, t0, dt):
    if _law(law) is None:
        return None
    spec, blocks, columns = _parts(law)
    kernel = spec.modules["state"].update_particles  # compiled on its own (not inlined), as when called by name
    if "state" not in blocks:
        def impl(law, elapsed, T0, T_rate, T, radius, radius_ref, state, uniform, params, t0, dt):
            return kernel(elapsed, T0, T_rate, T, radius, radius_ref, state, uniform, params, t0, dt)
        return impl
    start, stop = _bounds(spec)[blocks["state"]]

    def impl(law, elapsed, T0, T_rate, T, radius, radius_ref, state, uniform, params, t0, dt):
        return kernel(elapsed, T0, T_rate, T, radius, radius_ref, state, uniform, params[start:stop], t0, dt)
    return impl


overload(update_particles, inline="always")(_update_particles)


def _constant(value):
    def impl(law):
        return value
    return impl


def _spins(law):
    if _law(law) is not None:
        return _constant(bool(_law(law).SPINS))


overload(spins, inline="always")(_spins)


def _has_drag(law):
    if _law(law) is not None:
        return _constant(bool(_law(law).DRAG))


overload(has_drag, inline="always")(_has_drag)


def _keeps_pair_constants(law):
    if _law(law) is not None:
        return _constant(len(_law(law).PAIR_CONSTANTS) > 0)


overload(keeps_pair_constants, inline="always")(_keeps_pair_constants)


def _block(start, stop, whole):
    """``params -> (block,)``: the block ``params[start:stop]`` as a tuple (``whole``: the block is the array)."""
    size = stop - start
    if whole:
        return njit(inline="always")(lambda params: (to_fixed_tuple(params, size),))
    return njit(inline="always")(lambda params: (to_fixed_tuple(params[start:stop], size),))


def _joined(first, then):
    """``params -> first(params) + then(params)``."""
    return njit(inline="always")(lambda params: first(params) + then(params))


def _params_tuple(law, params):
    if _law(law) is None:
        return None
    bounds = _bounds(_law(law))
    blocks = _block(*bounds[0], len(bounds) == 1)
    for start, stop in bounds[1:]:
        blocks = _joined(blocks, _block(start, stop, False))

    def impl(law, params):
        return blocks(params)
    return impl


overload(params_tuple, inline="always")(_params_tuple)
