"""Vision tracker: detectors, tracking backends, re-acquisition, box Kalman, datasets, metrics."""
from tracker.registry import available_trackers, make_tracker
from tracker.subject import SubjectTracker

__all__ = ["SubjectTracker", "available_trackers", "make_tracker"]
