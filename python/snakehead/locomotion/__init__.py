"""Moving the body over the ground: gaits for any snake of alternating yaw and pitch joints (:mod:`.gaits`: the
serpenoid family; rolling, sidewinding, turning in place), where a lying body must go and the next gait that takes
it there (:mod:`.goals`), and the body's path around the scene's obstacles (:mod:`.ground_path`)."""
from .gaits import GAITS, Gait, Wave, make_gait, virtual_chassis

__all__ = ["GAITS", "Gait", "Wave", "make_gait", "virtual_chassis"]
