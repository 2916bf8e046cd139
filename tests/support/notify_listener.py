"""A stand-in for systemd's notification socket (NOTIFY_SOCKET): binds SOCKET, prints each
datagram on one line, and ends after STOPPING=1 or TIMEOUT seconds of silence.
   notify_listener.py SOCKET [TIMEOUT]"""
import os
import socket
import sys

s = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
s.bind(sys.argv[1])
os.chmod(sys.argv[1], 0o666)  # the daemon may run as another user
s.settimeout(float(sys.argv[2]) if len(sys.argv) > 2 else 600)
while True:
    message = s.recv(4096).decode()
    print(message.replace("\n", " "), flush=True)
    if "STOPPING=1" in message:
        break
