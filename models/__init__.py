"""Mechanics: lattices of rigid disks, contacts, the MLCP of an event, event-driven evolution."""
