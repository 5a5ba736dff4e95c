"""The canonical point of a non-unique solution set: face selection (face.py), its small dense
LP/QP coordinates (face_coords.py) and the HiGHS/Clarabel reference path (face_reference.py)."""
