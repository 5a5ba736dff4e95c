"""The paper's Sec. IV, reproduced: experiments at the captions' parameters, claims judged by
stated criteria, figures and a report. `rigidlcp reproduce` is its command
(rigidlcp/cli/reproduce.py)."""
