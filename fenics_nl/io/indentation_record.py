"""The JSON record of a punch run: the loaded state, its check against Hertz, the steps.

The keys every punch demo writes (`demos/punch.py` writes them in its own cells): the state
at the largest load, the work summed over the steps, the curve P(δ) of every converged step
(loading, then unloading) and Hertz's values with the relative errors.
"""

from __future__ import annotations

__all__ = ["REACTIONS_OF", "record"]

# what a punch's reactions are the forces of, by model and [tangential load]: the modelled
# part's, or the whole body's where the residual carries it (2πr)
REACTIONS_OF = {"axisymmetric": ("the whole body (2πr in the residual)",) * 2,
                "3d": ("the modelled quarter", "the modelled half"),
                "plane_strain": ("the modelled half, per unit length",
                                 "the whole block, per unit length")}


def record(states: list, loaded, check, *, model: str, formulation: str, material: str,
           mixed: bool, h: float, nodes: int) -> dict:
    """The quantities of a punch run, JSON-able.

    Args:
        states: every converged state (`contact.obstacles.Indentation`), loading then
            unloading.
        loaded: the state at the largest load.
        check: its comparison with Hertz (`ref`, `errors`, `exponent`; `ref` None: no
            contact).
        model: ``axisymmetric``, ``3d`` or ``plane_strain``.
        formulation: ``elimination`` or ``multiplier``.
        material: the law's name.
        mixed: Taylor–Hood elements.
        h: the element size under the punch.
        nodes: the nodes in contact at the largest load.

    Returns:
        The record of the loaded state, the work, the histories, the steps, Hertz's values
        and the relative errors (``hertz_<k>``, ``<k>_rel_error``) and the fitted exponent.
    """
    out = {"model": model, "formulation": formulation, "material": material,
           "mixed": mixed, "elements": "P2-P1 (Taylor-Hood)" if mixed else "P1",
           **{k: getattr(loaded, k) for k in ("force", "indentation", "contact_radius",
                                              "max_pressure")},
           "element_size": h, "nodes_in_contact": nodes,
           **{k: sum(getattr(s, k) for s in states)
              for k in ("active_set_iterations", "newton_iterations", "factorizations")},
           "indentation_history": [s.indentation for s in states],
           "force_history": [s.force for s in states],
           "steps": [{k: getattr(s, k) for k in ("indentation", "force", "contact_radius",
                                                 "active_set_iterations")} for s in states]}
    for k, error in check.errors.items():
        out[f"hertz_{k}"], out[f"{k}_rel_error"] = check.ref[k], error
    if check.exponent is not None:
        out["fitted_exponent"] = check.exponent
    return out
