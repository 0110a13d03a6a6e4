"""Path preparation, velocity planning and interpolation (the GEO task's path part).

Modules, one concept each:

* ``geometry``: Line and Arc elements (length, point at a path length, tangents).
* ``offsets``: offset curves of lines and arcs (offset, intersect, trim).
* ``compensation``: tool radius compensation G41/G42/G40, streaming.
* ``limits``: axis dynamics, element speed/acceleration limits, junction limit,
  software limit switches.
* ``segments``: blocks -> planning segments (validation, compensation, limits).
* ``planner``: the velocity planning model, the look-ahead buffer's backward pass and
  the whole-program reference plan (``plan_time_optimal``).
* ``profile``: the closed-form speed profile within one segment.
* ``interpolator``: the fixed-cycle motion along the plan (block ends, dwell, stops).
* ``executor``: ``PathExecutor``, the façade the channel's cycle calls.
"""

from .errors import PathError, PathErrorId
from .executor import PathExecutor
from .interpolator import StepResult, Waiting
from .limits import AxisDynamics
from .planner import plan_profile, plan_time_optimal

__all__ = ["AxisDynamics", "PathError", "PathErrorId", "PathExecutor", "StepResult",
           "Waiting", "plan_profile", "plan_time_optimal"]
